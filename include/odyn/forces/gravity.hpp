#pragma once
// Uniform gravity on every body: a force m g at each centre of mass.

#include <string>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"

namespace odyn {

template <class SpaceT>
class GravityField {
 public:
  using Space = SpaceT;
  using Vector = typename Space::Vector;

  static constexpr std::array<Parameter, 2> parameter_list{{
      {"name", "name", nullptr, "", "the element's name"},
      {"acceleration", "vector", nullptr, "m/s^2", "the acceleration of gravity"},
  }};
  static constexpr ElementDescription description{
      "gravity", "force", "Uniform gravity: a force m g at every body's centre of mass.",
      parameter_list};
  template <class Reader>
  static GravityField from_parameters(Reader& r) {
    return GravityField(parameter<std::string>(r, "name"), parameter<Vector>(r, "acceleration"));
  }

  GravityField(std::string name, const Vector& acceleration)
      : name_(std::move(name)), g_(acceleration) {
    if (!g_.allFinite()) throw ModelError(name_, "gravity vector is not finite");
  }

  const std::string& name() const { return name_; }
  const Vector& acceleration() const { return g_; }

  typename Space::Velocity force_on(double mass, const typename Space::Frame&) const {
    typename Space::Velocity q = Space::Velocity::Zero();
    q.template head<Space::dim>() = mass * g_;
    return q;
  }

  double potential_energy(double mass, const typename Space::Frame& frame) const {
    return -mass * g_.dot(frame.position);
  }

 private:
  std::string name_;
  Vector g_;
};

}  // namespace odyn
