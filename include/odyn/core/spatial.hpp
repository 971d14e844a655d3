#pragma once
// The spatial (3-D) body space: what a body's coordinates are and how they move.
//
// Configuration of a body: position of its centre of mass in the global frame and a unit
// quaternion (w, x, y, z) — 7 numbers. Velocity: linear velocity of the centre of mass in the
// global frame and angular velocity in the body frame — 6 numbers, the paper's six coordinates.
// The mass block diag(m I, J) is then constant, and positions live on R^3 x SO(3).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "odyn/core/rotation.hpp"

namespace odyn {

struct Spatial {
  static constexpr int dim = 3;      // dimension of points and forces
  static constexpr int nq = 7;       // configuration numbers per body
  static constexpr int nv = 6;       // velocity numbers per body (linear, then angular)
  static constexpr int linear = 0;   // offset of the linear part in a body's velocity
  static constexpr int angular = 3;  // offset of the angular part
  static constexpr int nw = 3;       // size of the angular part
  /// Names of a body's velocity numbers, for reports: travels along the global axes, turns
  /// about the body's own.
  static constexpr std::array<const char*, nv> velocity_labels{"x", "y", "z", "rx", "ry", "rz"};

  using Vector = Eigen::Vector3d;          // a point or a free vector
  using Angular = Eigen::Vector3d;         // an angular velocity or a torque
  using RotationMatrix = Eigen::Matrix3d;  // body-to-global rotation
  using Inertia = Eigen::Matrix3d;         // about the centre of mass, body frame
  using Configuration = Eigen::Matrix<double, nq, 1>;
  using Velocity = Eigen::Matrix<double, nv, 1>;
  using PointJacobian = Eigen::Matrix<double, dim, nv>;
  using MassBlock = Eigen::Matrix<double, nv, nv>;

  /// Kinematic snapshot of one body, computed once per evaluation and read by every element.
  struct Frame {
    using Vector = Spatial::Vector;
    Vector position = Vector::Zero();                      // centre of mass, global
    RotationMatrix rotation = RotationMatrix::Identity();  // body to global
    Vector linear_velocity = Vector::Zero();               // global
    Angular angular_velocity = Angular::Zero();            // body frame

    /// Global position of a point given in body coordinates.
    Vector point(const Vector& local) const { return position + rotation * local; }
    /// Global velocity of a body-fixed point.
    Vector point_velocity(const Vector& local) const {
      return linear_velocity + rotation * angular_velocity.cross(local);
    }
    /// A body-fixed direction in global coordinates.
    Vector direction(const Vector& local) const { return rotation * local; }
    /// Time derivative of a body-fixed direction, global.
    Vector direction_rate(const Vector& local) const {
      return rotation * angular_velocity.cross(local);
    }
    /// Velocity-independent part of a body-fixed vector's second derivative:
    /// d2/dt2 (R a) = R (w' x a) + R (w x (w x a)); this returns the second term.
    Vector centripetal(const Vector& local) const {
      return rotation * angular_velocity.cross(angular_velocity.cross(local));
    }
    /// d(point velocity)/d(body velocity): [I, -R skew(s)].
    PointJacobian point_jacobian(const Vector& local) const {
      PointJacobian jacobian;
      jacobian.leftCols<3>().setIdentity();
      jacobian.rightCols<3>() = -rotation * skew(local);
      return jacobian;
    }
    /// How point_jacobian(s)^T g, the generalized force of a fixed global force g at the point,
    /// changes with the body's velocity coordinates: only its torque s x R^T g turns with the
    /// body, by skew(s) skew(R^T g).
    MassBlock point_jacobian_derivative(const Vector& local, const Vector& global) const {
      MassBlock derivative = MassBlock::Zero();
      derivative.bottomRightCorner<3, 3>() = skew(local) * skew(rotation.transpose() * global);
      return derivative;
    }
    /// Global angular velocity.
    Vector global_angular_velocity() const { return rotation * angular_velocity; }
    /// Generalized force of a global torque (the body velocity's angular part is body-frame).
    Angular torque_to_body(const Vector& global_torque) const {
      return rotation.transpose() * global_torque;
    }
  };

  /// A force and a torque (both global unless said otherwise).
  struct Wrench {
    Vector force = Vector::Zero();
    Vector torque = Vector::Zero();
  };

  /// The wrench, at a body point, that a generalized force (global force at the centre of
  /// mass, body-frame torque) stands for.
  static Wrench wrench_at(const Frame& frame, const Vector& local_point,
                          const Velocity& generalized) {
    Wrench wrench;
    wrench.force = generalized.head<3>();
    wrench.torque =
        frame.rotation * generalized.tail<3>() - (frame.rotation * local_point).cross(wrench.force);
    return wrench;
  }

  /// A global wrench in the axes whose columns (global) are `axes`.
  static Wrench in_axes(const Wrench& wrench, const RotationMatrix& axes) {
    return {axes.transpose() * wrench.force, axes.transpose() * wrench.torque};
  }

  static Configuration identity() {
    Configuration q = Configuration::Zero();
    q[3] = 1.0;
    return q;
  }

  static Eigen::Quaterniond orientation(const Eigen::Ref<const Configuration>& q) {
    return {q[3], q[4], q[5], q[6]};
  }

  /// Fills a frame from a body's configuration and velocity.
  static void make_frame(const Eigen::Ref<const Configuration>& q,
                         const Eigen::Ref<const Velocity>& v, Frame& frame) {
    frame.position = q.head<3>();
    frame.rotation = orientation(q).toRotationMatrix();
    frame.linear_velocity = v.head<3>();
    frame.angular_velocity = v.tail<3>();
  }

  /// How far a body moved from q_from to q_to: the distance of its origin and the angle of the
  /// rotation between the two orientations (rad, in [0, pi]).
  static std::array<double, 2> displacement(const Eigen::Ref<const Configuration>& q_from,
                                            const Eigen::Ref<const Configuration>& q_to) {
    const Eigen::Quaterniond turn = orientation(q_from).conjugate() * orientation(q_to);
    return {(q_to.head<3>() - q_from.head<3>()).norm(),
            2.0 * std::atan2(turn.vec().norm(), std::abs(turn.w()))};
  }

  /// q_out = q_in composed with exp(increment): translation in the global frame, rotation
  /// applied on the right (body frame), so unit length holds to rounding error.
  static void integrate(const Eigen::Ref<const Configuration>& q_in,
                        const Eigen::Ref<const Velocity>& increment,
                        Eigen::Ref<Configuration> q_out) {
    q_out.head<3>() = q_in.head<3>() + increment.head<3>();
    Eigen::Quaterniond rotated = orientation(q_in) * quaternion_exp(increment.tail<3>());
    rotated.normalize();  // removes rounding only; the exponential keeps unit length
    q_out.tail<4>() << rotated.w(), rotated.x(), rotated.y(), rotated.z();
  }

  /// dq/dt for a velocity: the centre of mass moves with v, the quaternion turns as
  /// q' = q (0, w) / 2. Explicit integrators step q in R^7 with it and renormalize.
  static Configuration configuration_rate(const Eigen::Ref<const Configuration>& q,
                                          const Eigen::Ref<const Velocity>& v) {
    Configuration rate;
    rate.head<3>() = v.head<3>();
    const Eigen::Quaterniond turned = orientation(q) * Eigen::Quaterniond(0.0, v[3], v[4], v[5]);
    rate.tail<4>() << 0.5 * turned.w(), 0.5 * turned.x(), 0.5 * turned.y(), 0.5 * turned.z();
    return rate;
  }

  /// The velocity-space increment whose configuration_rate at q is dq, the inverse of that
  /// linear map on its range: dq's part along the quaternion itself (a change of its length,
  /// which normalize() removes) is dropped.
  static Velocity increment_of(const Eigen::Ref<const Configuration>& q,
                               const Eigen::Ref<const Configuration>& dq) {
    const Eigen::Quaterniond turn =
        orientation(q).conjugate() * Eigen::Quaterniond(dq[3], dq[4], dq[5], dq[6]);
    Velocity increment;
    increment << dq.head<3>(), 2.0 * turn.vec();
    return increment;
  }

  /// Magnitudes of the coordinates that the velocity components move, for relative error
  /// tolerances: the centre of mass's, and 1 for the rotation (radians).
  static Velocity coordinate_scale(const Eigen::Ref<const Configuration>& q) {
    Velocity scale;
    scale << q.head<3>().cwiseAbs(), 1.0, 1.0, 1.0;
    return scale;
  }

  /// The nearest valid configuration: the quaternion scaled to unit length.
  static void normalize(Eigen::Ref<Configuration> q) { q.tail<4>().normalize(); }

  static MassBlock mass_block(double mass, const Inertia& inertia) {
    MassBlock m = MassBlock::Zero();
    m.topLeftCorner<3, 3>().diagonal().setConstant(mass);
    m.bottomRightCorner<3, 3>() = inertia;
    return m;
  }

  /// M v for one body without forming M.
  static Velocity mass_times(double mass, const Inertia& inertia, const Velocity& v) {
    Velocity out;
    out.head<3>() = mass * v.head<3>();
    out.tail<3>().noalias() = inertia * v.tail<3>();
    return out;
  }

  /// Gyroscopic generalized force -w x (J w), which the body itself contributes to Q.
  static Velocity gyroscopic_force(const Inertia& inertia, const Frame& frame) {
    Velocity q = Velocity::Zero();
    const Angular& w = frame.angular_velocity;
    q.tail<3>() = -w.cross(inertia * w);
    return q;
  }

  /// -d(gyroscopic force)/d(velocity) = skew(w) J - skew(J w), for the Newton matrix.
  static MassBlock gyroscopic_damping(const Inertia& inertia, const Frame& frame) {
    MassBlock c = MassBlock::Zero();
    const Angular& w = frame.angular_velocity;
    c.bottomRightCorner<3, 3>() = skew(w) * inertia - skew(inertia * w);
    return c;
  }
};

}  // namespace odyn
