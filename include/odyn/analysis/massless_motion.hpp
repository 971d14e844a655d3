#pragma once
// Point masses and slender rods lack inertia in some directions (a point mass in every one, a
// rod about its axis). The model stands a moment in for the missing one (Body::massless), and
// the motion is then exact as long as nothing turns the body that way: its spin there stays
// zero, no force reaches the stand-in and it carries no energy. A joint that holds the body's
// orientation to a turning body, or a force off its centre or its axis, would spin it there and
// give the stand-in's inertia a say in the motion. This check, run at every output, refuses
// such a model by the body's name: the stand-in's kinetic energy must stay below 1e-9 of the
// largest kinetic energy of the run so far.

#include <algorithm>
#include <string>

#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/workspace.hpp"

namespace odyn {

template <class Model>
class MasslessMotionCheck {
 public:
  static constexpr double tolerance = 1e-9;

  /// Throws ModelError naming the first point mass or slender rod the motion spins where it has
  /// no inertia.
  void operator()(const Model& model, const Workspace<Model>& ws) {
    if (!model.has_massless_bodies()) return;
    constexpr int nv = Model::nv;
    peak_energy_ = std::max(peak_energy_, kinetic_energy(model, ws));
    for (int b = 1; b <= model.num_bodies(); ++b) {
      const auto& massless = model.massless(BodyId{b});
      if (massless.count == 0) continue;
      const auto v = ws.v.template segment<nv>((b - 1) * nv);
      const auto spin = massless.along(angular_part(v));
      const double energy = 0.5 * massless.stand_in * spin.squaredNorm();
      if (!(energy <= tolerance * peak_energy_))
        refuse(model.body(BodyId{b}).name, massless, ws.t, spin.norm(), energy);
    }
  }

 private:
  template <class V>
  static auto angular_part(const V& v) {
    if constexpr (Model::nv == 6)
      return Eigen::Vector3d(v.template tail<3>());
    else
      return v[2];
  }

  template <class Massless>
  [[noreturn]] void refuse(const std::string& body, const Massless& massless, double t, double spin,
                           double energy) const {
    const bool point = std::string(massless.what()) == "point mass";
    throw ModelError(
        body,
        std::string("a ") + massless.what() + " has no inertia to turn " +
            (point ? "with" : "about its axis") + ", yet the motion turns it so (at " +
            to_text(spin) + " rad/s at t = " + to_text(t) + " s, the stand-in moment's " +
            "energy is " + to_text(energy / std::max(peak_energy_, 1e-300)) +
            " of the largest kinetic energy). A joint that holds its orientation to another " +
            "body, or a force or joint point off its " + (point ? "centre" : "axis") +
            ", does that. " +
            (point ? "Attach a point mass at its centre with point joints (spherical, "
                     "distance, in_line, in_plane)"
                   : "Attach a slender rod on its axis with joints that leave its spin "
                     "free (spherical) or keep it still (a hinge across it)") +
            ", or give it a rigid body's inertia (see docs/bodies.md)");
  }

  double peak_energy_ = 0.0;
};

}  // namespace odyn
