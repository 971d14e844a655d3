#pragma once
// Bushing: a six-component spring-damper between a joint frame on body a and one on body b
// (forces/bushing_law.hpp gives the law). Its displacement x = (d, theta) is frame b's origin
// in a's axes, d = R_a^T (p_b - p_a), and the rotation vector of b's axes relative to a's,
// theta = log(R_a^T R_b), in a's axes; it rests where the two frames coincide. A frame's axes
// are its body's unless given (the reference left out is the body's x axis, or y if the frame's
// axis is along x): unlike a joint's, they are not taken from the initial pose, so that a body
// started away from rest starts loaded. The law's
// generalized force g = (g_d, g_theta) acts on b at its frame's origin, with the opposite on a
// at the same point:
//     force  R_a g_d,   torque  R_a J_l^{-T}(theta) g_theta,
// J_l being SO(3)'s left Jacobian. That torque is the one whose power is g_theta . theta', so the
// spring stays conservative and the damper dissipative at any angle below a half turn (for small
// angles J_l = I and the bushing is ADAMS's); beyond pi the rotation vector flips to the other
// side. Stiffness and damping blocks for implicit integrators come by central differences.

#include <Eigen/Core>
#include <string>
#include <utility>

#include "odyn/core/difference_jacobians.hpp"
#include "odyn/core/rotation.hpp"
#include "odyn/forces/bushing_law.hpp"
#include "odyn/spatial/pair_joint.hpp"

namespace odyn::spatial {

class Bushing : public PairJoint {
 public:
  using Law = BushingLaw<6>;
  using Vector6 = Law::Vector;

  static constexpr std::array<Parameter, 9> parameter_list =
      join(parameters::bushing_frames, parameters::bushing_law);
  static constexpr ElementDescription description{
      "bushing", "force",
      "Six-component spring-damper between frame a and frame b: force and torque on b "
      "-K x - C x' + preload + law(t, x, x'), x = (b's origin in a's axes, rotation vector).",
      parameter_list};
  template <class Reader>
  static Bushing from_parameters(Reader& r) {
    return parameters::from_frame_pair<Bushing, JointFrame>(r, Law::from_parameters(r));
  }

  Bushing(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
          const JointFrame& on_b, Law law)
      : PairJoint(std::move(name), body_a, with_reference(on_a), body_b, with_reference(on_b)),
        law_(std::move(law)) {
    law_.check(name_);
  }

  /// The displacement x of frame b relative to frame a and its rate x'.
  struct Displacement {
    Vector6 x;
    Vector6 rate;
  };

  Displacement displacement(const Input& in) const { return kinematics(in).displacement; }

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    const Kinematics k = kinematics(in);
    const Vector6 g = law_.force(in.t, k.displacement.x, k.displacement.rate);
    const Eigen::Vector3d force = k.axes_a * g.head<3>();
    const Eigen::Vector3d torque =
        k.axes_a * (left_jacobian_inverse(k.displacement.x.tail<3>()).transpose() * g.tail<3>());
    const auto &a = in.body(0), &b = in.body(1);
    out.force[0] << -force,
        a.rotation.transpose() * (-torque - (k.origin_b - a.position).cross(force));
    out.force[1] << force,
        b.rotation.transpose() * (torque + (k.origin_b - b.position).cross(force));
  }

  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    difference_jacobians(*this, in, out);
  }

  double potential_energy(const Input& in) const {
    return law_.potential_energy(kinematics(in).displacement.x);
  }

  const Law& law() const { return law_; }

 private:
  /// The frame with its reference filled in from the body's axes (see the file comment).
  static JointFrame with_reference(JointFrame frame) {
    if (frame.reference.squaredNorm() == 0.0 && frame.axis.allFinite())
      frame.reference = frame.axis.cross(Eigen::Vector3d::UnitX()).norm() > 1e-6 * frame.axis.norm()
                            ? Eigen::Vector3d::UnitX()
                            : Eigen::Vector3d::UnitY();
    return frame;
  }

  struct Kinematics {
    Space::RotationMatrix axes_a;  // frame a's axes, global columns
    Eigen::Vector3d origin_b;      // frame b's origin, global
    Displacement displacement;
  };

  Kinematics kinematics(const Input& in) const {
    const auto &a = in.body(0), &b = in.body(1);
    Kinematics k;
    k.axes_a = axes(0, a);
    k.origin_b = b.point(on_b_.point);
    const Eigen::Vector3d d = k.axes_a.transpose() * (k.origin_b - a.point(on_a_.point));
    const Eigen::Vector3d theta = rotation_log(k.axes_a.transpose() * axes(1, b));
    // d' = R_a^T (p_b' - p_a') - omega_a x d and theta' = J_l^{-1} omega, with the angular
    // velocities in a's axes (omega: b's relative to a's).
    const Eigen::Vector3d omega_a = k.axes_a.transpose() * a.global_angular_velocity();
    const Eigen::Vector3d omega = k.axes_a.transpose() * b.global_angular_velocity() - omega_a;
    const Eigen::Vector3d d_rate =
        k.axes_a.transpose() * (b.point_velocity(on_b_.point) - a.point_velocity(on_a_.point)) -
        omega_a.cross(d);
    k.displacement.x << d, theta;
    k.displacement.rate << d_rate, left_jacobian_inverse(theta) * omega;
    return k;
  }

  Law law_;
};
static_assert(StatelessForce<Bushing> && HasForceJacobians<Bushing> && HasPotential<Bushing>);

}  // namespace odyn::spatial
