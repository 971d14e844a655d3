#pragma once
// Planar bushing: a three-component spring-damper between a joint frame on body a and one on
// body b (forces/bushing_law.hpp gives the law), the spatial bushing's twin. Its displacement
// x = (d, theta) is frame b's origin in a's axes, d = R_a^T (p_b - p_a), and the joint angle
// from a's axis to b's (PairJoint::angle, counting turns); it rests where the frames coincide.
// An axis left out is the body's x axis (not, as for a joint, the other body's at the initial
// pose), so that a body started away from rest starts loaded.
// The law's generalized force g = (g_d, g_theta) acts on b at its frame's origin, the force
// R_a g_d and the torque g_theta, with the opposite on a at the same point.
// Stiffness and damping blocks for implicit integrators come by central differences.

#include <Eigen/Core>
#include <string>
#include <utility>

#include "odyn/core/difference_jacobians.hpp"
#include "odyn/forces/bushing_law.hpp"
#include "odyn/planar/pair_joint.hpp"

namespace odyn::planar {

class Bushing : public PairJoint {
 public:
  using Law = BushingLaw<3>;
  using Vector3 = Law::Vector;

  static constexpr std::array<Parameter, 9> parameter_list =
      join(parameters::bushing_frames, parameters::bushing_law);
  static constexpr ElementDescription description{
      "bushing", "force",
      "Three-component spring-damper between frame a and frame b: force and torque on b "
      "-K x - C x' + preload + law(t, x, x'), x = (b's origin in a's axes, joint angle).",
      parameter_list};
  template <class Reader>
  static Bushing from_parameters(Reader& r) {
    return parameters::from_frame_pair<Bushing, JointFrame>(r, Law::from_parameters(r));
  }

  Bushing(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
          const JointFrame& on_b, Law law)
      : PairJoint(std::move(name), body_a, with_axis(on_a), body_b, with_axis(on_b)),
        law_(std::move(law)) {
    law_.check(name_);
  }

  /// The displacement x of frame b relative to frame a and its rate x'.
  struct Displacement {
    Vector3 x;
    Vector3 rate;
  };

  Displacement displacement(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    const Space::RotationMatrix axes_a = axes(0, a);
    const Vector d = axes_a.transpose() * (b.point(on_b_.point) - a.point(on_a_.point));
    // d' = R_a^T (p_b' - p_a') - phi_a' perpendicular(d).
    const Vector d_rate =
        axes_a.transpose() * (b.point_velocity(on_b_.point) - a.point_velocity(on_a_.point)) -
        a.omega() * Space::perpendicular(d);
    Displacement out;
    out.x << d, angle(in);
    out.rate << d_rate, angle_rate(in);
    return out;
  }

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    const Displacement x = displacement(in);
    const Vector3 g = law_.force(in.t, x.x, x.rate);
    const auto &a = in.body(0), &b = in.body(1);
    const Vector force = axes(0, a) * g.head<2>();
    const Vector origin_b = b.point(on_b_.point);
    out.force[0] << -force, -g[2] - Space::cross(origin_b - a.position, force);
    out.force[1] << force, g[2] + Space::cross(origin_b - b.position, force);
  }

  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    difference_jacobians(*this, in, out);
  }

  double potential_energy(const Input& in) const {
    return law_.potential_energy(displacement(in).x);
  }

  const Law& law() const { return law_; }

 private:
  static JointFrame with_axis(JointFrame frame) {
    if (frame.axis.squaredNorm() == 0.0) frame.axis = Vector::UnitX();
    return frame;
  }

  Law law_;
};
static_assert(StatelessForce<Bushing> && HasForceJacobians<Bushing> && HasPotential<Bushing>);

}  // namespace odyn::planar
