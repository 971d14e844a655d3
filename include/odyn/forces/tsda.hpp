#pragma once
// Translational spring-damper-actuator between two body points. With L the distance and
// L' its rate, the tension f = k (L - free_length) + c L' + actuator(t, L, L') pulls the
// points together (a positive f is tension).

#include <cmath>
#include <functional>
#include <string>

#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/parameter_blocks.hpp"

namespace odyn {

template <class SpaceT>
class TsdaT {
 public:
  using Space = SpaceT;
  using Vector = typename Space::Vector;
  using Frame = typename Space::Frame;
  using Actuator = std::function<double(double t, double length, double rate)>;
  static constexpr int num_bodies = 2;
  using Input = ElementInput<Space, 2>;

  struct Parameters {
    double stiffness = 0.0;    // k, N/m
    double damping = 0.0;      // c, N s/m
    double free_length = 0.0;  // m
    Actuator actuator = {};    // extra tension, N (optional)
  };

  static constexpr std::array<Parameter, 9> parameter_list =
      join(parameters::point_pair, parameters::translational_spring);
  static constexpr std::array<Output, 3> output_list{{
      {"length", "m", "L, the distance between the points"},
      {"rate", "m/s", "L', positive as the points move apart"},
      {"tension", "N", "the tension, positive pulling the points together"},
  }};
  static constexpr ElementDescription description{
      "tsda", "force",
      "Translational spring-damper-actuator: the tension k (L - free_length) + c L' + "
      "actuator(t, L, L') pulls the points together.",
      parameter_list, output_list};
  template <class Reader>
  static TsdaT from_parameters(Reader& r) {
    return parameters::from_point_pair<TsdaT, Vector>(
        r, parameters::spring_law<Parameters>(r, "free_length"));
  }

  TsdaT(std::string name, BodyId body_a, const Vector& point_a, BodyId body_b,
        const Vector& point_b, Parameters parameters)
      : name_(std::move(name)),
        bodies_{body_a, body_b},
        point_a_(point_a),
        point_b_(point_b),
        p_(std::move(parameters)) {
    if (!std::isfinite(p_.stiffness) || !std::isfinite(p_.damping) ||
        !std::isfinite(p_.free_length) || p_.free_length < 0.0)
      throw ModelError(name_,
                       "stiffness, damping and free length must be finite, and the free "
                       "length not negative");
    if (!point_a_.allFinite() || !point_b_.allFinite())
      throw ModelError(name_, "attachment points must be finite");
  }

  const std::string& name() const { return name_; }
  const std::array<BodyId, 2>& bodies() const { return bodies_; }

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    const Geometry g = geometry(in);
    const double tension = tension_at(in.t, g);
    // Between coincident points a tension has no direction to act along: it would be dropped
    // while its spring still stores energy.
    if (g.length == 0.0 && tension != 0.0)
      throw ModelError(name_, "its points coincide at t = " + to_text(in.t) +
                                  " s, where its tension of " + to_text(tension) +
                                  " N has no direction; attach it at points apart (a free "
                                  "length needs a length to push along), or use a bushing, "
                                  "whose force has components");
    // Tension pulls b towards a and a towards b.
    out.force[0] = g.jacobian_a.transpose() * (tension * g.direction);
    out.force[1] = -g.jacobian_b.transpose() * (tension * g.direction);
  }

  /// Newton-matrix blocks from the spring and damper (the lever arms' own change is left out).
  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    const Geometry g = geometry(in);
    const double tension = p_.stiffness * (g.length - p_.free_length) + p_.damping * g.rate;
    using Square = Eigen::Matrix<double, Space::dim, Space::dim>;
    const Square along = g.direction * g.direction.transpose();
    const Square across = Square::Identity() - along;
    // d(force on b)/d(P_b - P_a), with the sign of -dQ/dq.
    const Square spring =
        p_.stiffness * along + (g.length > 0.0 ? tension / g.length : 0.0) * across;
    const Square damper = p_.damping * along;
    Eigen::Matrix<double, Space::dim, 2 * Space::nv> relative;  // d(P_b - P_a)/d(v_a, v_b)
    relative << -g.jacobian_a, g.jacobian_b;
    out.stiffness = relative.transpose() * spring * relative;
    out.damping = relative.transpose() * damper * relative;
  }

  double potential_energy(const Input& in) const {
    const double stretch = geometry(in).length - p_.free_length;
    return 0.5 * p_.stiffness * stretch * stretch;
  }

  std::array<double, 3> outputs(const Input& in) const {
    const Geometry g = geometry(in);
    return {g.length, g.rate, tension_at(in.t, g)};
  }

 private:
  struct Geometry {
    typename Space::PointJacobian jacobian_a, jacobian_b;
    Vector direction;  // unit, from a to b
    double length, rate;
  };
  double tension_at(double t, const Geometry& g) const {
    return p_.stiffness * (g.length - p_.free_length) + p_.damping * g.rate +
           (p_.actuator ? p_.actuator(t, g.length, g.rate) : 0.0);
  }
  Geometry geometry(const Input& in) const {
    const Frame &a = in.body(0), &b = in.body(1);
    const Vector d = b.point(point_b_) - a.point(point_a_);
    const Vector d_rate = b.point_velocity(point_b_) - a.point_velocity(point_a_);
    Geometry g;
    g.length = d.norm();
    g.direction = g.length > 0.0 ? Vector(d / g.length) : Vector(Vector::Zero());
    g.rate = g.direction.dot(d_rate);
    g.jacobian_a = a.point_jacobian(point_a_);
    g.jacobian_b = b.point_jacobian(point_b_);
    return g;
  }

  std::string name_;
  std::array<BodyId, 2> bodies_;
  Vector point_a_, point_b_;
  Parameters p_;
};

}  // namespace odyn
