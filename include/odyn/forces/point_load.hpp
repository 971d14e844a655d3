#pragma once
// A force at a body point, or a torque on a body: constant, or a function of time and of the
// body's frame (its pose and velocity). Given in the global frame or in body axes.

#include <functional>
#include <string>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"

namespace odyn {

enum class Axes { global, body };

template <class SpaceT>
class PointForceT {
 public:
  using Space = SpaceT;
  using Vector = typename Space::Vector;
  using Frame = typename Space::Frame;
  using Function = std::function<Vector(double t, const Frame& body)>;
  static constexpr int num_bodies = 1;

  static constexpr std::array<Parameter, 5> parameter_list{{
      {"name", "name", nullptr, "", "the element's name"},
      {"body", "body", nullptr, "", "the body it acts on"},
      {"force", "vector_or_callable", nullptr, "N",
       "the force: constant, or force(t, body) -> a vector"},
      {"point", "vector", "0", "m", "where it acts, in body coordinates"},
      {"axes", "axes", "\"global\"", "", "the axes the force is given in"},
  }};
  static constexpr ElementDescription description{
      "point_force", "force", "A force at a body point, constant or a function of time and state.",
      parameter_list};
  template <class Reader>
  static PointForceT from_parameters(Reader& r) {
    const auto name = parameter<std::string>(r, "name");
    const BodyId body = parameter<BodyId>(r, "body");
    const auto point = parameter<Vector>(r, "point");
    const Axes axes = parameter<Axes>(r, "axes");
    if (parameter_is_function(r, "force"))
      return PointForceT(name, body, point, parameter<Function>(r, "force"), axes);
    return PointForceT(name, body, point, parameter<Vector>(r, "force"), axes);
  }

  PointForceT(std::string name, BodyId body, const Vector& point, Function force,
              Axes axes = Axes::global)
      : name_(std::move(name)),
        bodies_{body},
        point_(point),
        force_(std::move(force)),
        axes_(axes) {
    if (!force_) throw ModelError(name_, "the force function is empty");
    if (!point_.allFinite()) throw ModelError(name_, "point is not finite");
  }
  PointForceT(std::string name, BodyId body, const Vector& point, const Vector& force,
              Axes axes = Axes::global)
      : PointForceT(std::move(name), body, point, constant(force), axes) {
    if (!force.allFinite()) throw ModelError(name_, "force is not finite");
  }

  const std::string& name() const { return name_; }
  const std::array<BodyId, 1>& bodies() const { return bodies_; }

  void evaluate(const ElementInput<Space, 1>& in, ForceBlocks<Space, 1>& out) const {
    const Frame& body = in.body(0);
    Vector f = force_(in.t, body);
    if (axes_ == Axes::body) f = body.direction(f);
    out.force[0] = body.point_jacobian(point_).transpose() * f;
  }

 private:
  static Function constant(const Vector& f) {
    return [f](double, const Frame&) { return f; };
  }
  std::string name_;
  std::array<BodyId, 1> bodies_;
  Vector point_;
  Function force_;
  Axes axes_;
};

template <class SpaceT>
class PointTorqueT {
 public:
  using Space = SpaceT;
  using Angular = typename Space::Angular;
  using Frame = typename Space::Frame;
  using Function = std::function<Angular(double t, const Frame& body)>;
  static constexpr int num_bodies = 1;

  static constexpr std::array<Parameter, 4> parameter_list{{
      {"name", "name", nullptr, "", "the element's name"},
      {"body", "body", nullptr, "", "the body it acts on"},
      {"torque", "angular_or_callable", nullptr, "N m",
       "the torque: constant, or torque(t, body) -> one"},
      {"axes", "axes", "\"global\"", "", "the axes the torque is given in (space only)"},
  }};
  static constexpr ElementDescription description{
      "point_torque", "force", "A torque on a body, constant or a function of time and state.",
      std::span<const Parameter>(parameter_list.data(), Space::nw == 3 ? 4 : 3)};
  template <class Reader>
  static PointTorqueT from_parameters(Reader& r) {
    const auto name = parameter<std::string>(r, "name");
    const BodyId body = parameter<BodyId>(r, "body");
    const Axes axes = Space::nw == 3 ? parameter<Axes>(r, "axes") : Axes::global;
    if (parameter_is_function(r, "torque"))
      return PointTorqueT(name, body, parameter<Function>(r, "torque"), axes);
    return PointTorqueT(name, body, parameter<Angular>(r, "torque"), axes);
  }

  PointTorqueT(std::string name, BodyId body, Function torque, Axes axes = Axes::global)
      : name_(std::move(name)), bodies_{body}, torque_(std::move(torque)), axes_(axes) {
    if (!torque_) throw ModelError(name_, "the torque function is empty");
  }
  PointTorqueT(std::string name, BodyId body, const Angular& torque, Axes axes = Axes::global)
      : PointTorqueT(std::move(name), body, constant(torque), axes) {
    if (!torque.allFinite()) throw ModelError(name_, "torque is not finite");
  }
  /// In the plane a torque is a number.
  PointTorqueT(std::string name, BodyId body, double torque) requires(Space::nw == 1)
      : PointTorqueT(std::move(name), body, Angular(Angular::Constant(torque))) {}
  PointTorqueT(std::string name, BodyId body,
               std::function<double(double t, const Frame&)> torque) requires(Space::nw == 1)
      : PointTorqueT(std::move(name), body, scalar(std::move(torque))) {}

  const std::string& name() const { return name_; }
  const std::array<BodyId, 1>& bodies() const { return bodies_; }

  void evaluate(const ElementInput<Space, 1>& in, ForceBlocks<Space, 1>& out) const {
    const Frame& body = in.body(0);
    const Angular torque = torque_(in.t, body);
    out.force[0].setZero();
    out.force[0].template tail<Space::nw>() =
        axes_ == Axes::body ? torque : body.torque_to_body(torque);
  }

 private:
  static Function constant(const Angular& t) {
    return [t](double, const Frame&) { return t; };
  }
  static Function scalar(std::function<double(double, const Frame&)> torque) {
    if (!torque) return {};
    return [torque = std::move(torque)](double t, const Frame& body) {
      return Angular::Constant(torque(t, body));
    };
  }
  std::string name_;
  std::array<BodyId, 1> bodies_;
  Function torque_;
  Axes axes_;
};

}  // namespace odyn
