#pragma once
// Uniform gravity on every body: a force m g at each centre of mass.

#include <string>

#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"

namespace odyn {

template <class SpaceT>
class GravityField {
 public:
  using Space = SpaceT;
  using Vector = typename Space::Vector;

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
