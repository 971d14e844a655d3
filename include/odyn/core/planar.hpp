#pragma once
// The planar body space: a rigid body moving in the x-y plane.
//
// Configuration of a body: position of its centre of mass and its angle phi (counter-clockwise)
// — 3 numbers. Velocity: linear velocity of the centre of mass and the angular velocity phi' —
// 3 numbers. Positions live on R^2 x R: the angle is an ordinary coordinate that keeps counting
// past a full turn, so configurations integrate by plain addition, and the mass block diag(m, m, I)
// is constant with no gyroscopic term.

#include <Eigen/Core>
#include <array>
#include <cmath>

namespace odyn {

struct Planar {
  static constexpr int dim = 2;      // dimension of points and forces
  static constexpr int nq = 3;       // configuration numbers per body (x, y, phi)
  static constexpr int nv = 3;       // velocity numbers per body (x', y', phi')
  static constexpr int linear = 0;   // offset of the linear part in a body's velocity
  static constexpr int angular = 2;  // offset of the angular part
  static constexpr int nw = 1;       // size of the angular part
  /// Names of a body's velocity numbers, for reports.
  static constexpr std::array<const char*, nv> velocity_labels{"x", "y", "angle"};

  using Vector = Eigen::Vector2d;               // a point or a free vector
  using Angular = Eigen::Matrix<double, 1, 1>;  // an angular velocity or a torque
  using RotationMatrix = Eigen::Matrix2d;       // body-to-global rotation
  using Inertia = double;                       // about the centre of mass
  using Configuration = Eigen::Matrix<double, nq, 1>;
  using Velocity = Eigen::Matrix<double, nv, 1>;
  using PointJacobian = Eigen::Matrix<double, dim, nv>;
  using MassBlock = Eigen::Matrix<double, nv, nv>;

  /// The vector turned by +90 degrees: d/dphi (R(phi) a) = perpendicular(R(phi) a).
  static Vector perpendicular(const Vector& a) { return {-a.y(), a.x()}; }
  /// z component of the cross product of two plane vectors.
  static double cross(const Vector& a, const Vector& b) { return a.x() * b.y() - a.y() * b.x(); }
  static RotationMatrix rotation(double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    RotationMatrix r;
    r << c, -s, s, c;
    return r;
  }

  /// Kinematic snapshot of one body, computed once per evaluation and read by every element.
  struct Frame {
    using Vector = Planar::Vector;
    Vector position = Vector::Zero();                      // centre of mass
    double angle = 0.0;                                    // phi, counter-clockwise
    RotationMatrix rotation = RotationMatrix::Identity();  // body to global
    Vector linear_velocity = Vector::Zero();
    Angular angular_velocity = Angular::Zero();

    double omega() const { return angular_velocity[0]; }
    /// Global position of a point given in body coordinates.
    Vector point(const Vector& local) const { return position + rotation * local; }
    /// Global velocity of a body-fixed point.
    Vector point_velocity(const Vector& local) const {
      return linear_velocity + omega() * perpendicular(rotation * local);
    }
    /// A body-fixed direction in global coordinates.
    Vector direction(const Vector& local) const { return rotation * local; }
    /// Time derivative of a body-fixed direction.
    Vector direction_rate(const Vector& local) const {
      return omega() * perpendicular(rotation * local);
    }
    /// Velocity-dependent part of a body-fixed vector's second derivative: -phi'^2 R a.
    Vector centripetal(const Vector& local) const {
      return -omega() * omega() * (rotation * local);
    }
    /// d(point velocity)/d(body velocity): [I, perpendicular(R s)].
    PointJacobian point_jacobian(const Vector& local) const {
      PointJacobian jacobian;
      jacobian.leftCols<2>().setIdentity();
      jacobian.col(2) = perpendicular(rotation * local);
      return jacobian;
    }
    /// How point_jacobian(s)^T g, the generalized force of a fixed force g at the point,
    /// changes with the body's velocity coordinates: its torque g . perpendicular(R s) turns
    /// with the body, by -g . (R s).
    MassBlock point_jacobian_derivative(const Vector& local, const Vector& global) const {
      MassBlock derivative = MassBlock::Zero();
      derivative(2, 2) = -global.dot(rotation * local);
      return derivative;
    }
    Angular global_angular_velocity() const { return angular_velocity; }
    /// Generalized force of a torque (in the plane, global and body torques are the same).
    Angular torque_to_body(const Angular& torque) const { return torque; }
  };

  /// A force and a torque about the plane's normal.
  struct Wrench {
    Vector force = Vector::Zero();
    Angular torque = Angular::Zero();
  };

  /// The wrench, at a body point, that a generalized force (force at the centre of mass, torque)
  /// stands for.
  static Wrench wrench_at(const Frame& frame, const Vector& local_point,
                          const Velocity& generalized) {
    Wrench wrench;
    wrench.force = generalized.head<2>();
    wrench.torque[0] = generalized[2] - cross(frame.rotation * local_point, wrench.force);
    return wrench;
  }

  /// A wrench in the axes whose columns (global) are `axes`.
  static Wrench in_axes(const Wrench& wrench, const RotationMatrix& axes) {
    return {axes.transpose() * wrench.force, wrench.torque};
  }

  static Configuration identity() { return Configuration::Zero(); }

  /// Fills a frame from a body's configuration and velocity.
  static void make_frame(const Eigen::Ref<const Configuration>& q,
                         const Eigen::Ref<const Velocity>& v, Frame& frame) {
    frame.position = q.head<2>();
    frame.angle = q[2];
    frame.rotation = rotation(q[2]);
    frame.linear_velocity = v.head<2>();
    frame.angular_velocity[0] = v[2];
  }

  /// How far a body moved from q_from to q_to: the distance of its origin and the angle it
  /// turned (rad; whole turns count, as the angle coordinate does).
  static std::array<double, 2> displacement(const Eigen::Ref<const Configuration>& q_from,
                                            const Eigen::Ref<const Configuration>& q_to) {
    return {(q_to.head<2>() - q_from.head<2>()).norm(), std::abs(q_to[2] - q_from[2])};
  }

  /// q_out = q_in + increment: the plane's motions commute, so the group is a vector space.
  static void integrate(const Eigen::Ref<const Configuration>& q_in,
                        const Eigen::Ref<const Velocity>& increment,
                        Eigen::Ref<Configuration> q_out) {
    q_out = q_in + increment;
  }

  /// dq/dt for a velocity: the velocity itself.
  static Configuration configuration_rate(const Eigen::Ref<const Configuration>&,
                                          const Eigen::Ref<const Velocity>& v) {
    return v;
  }

  /// The velocity-space increment whose configuration_rate is dq: dq itself.
  static Velocity increment_of(const Eigen::Ref<const Configuration>&,
                               const Eigen::Ref<const Configuration>& dq) {
    return dq;
  }

  /// Magnitudes of the coordinates that the velocity components move, for relative error
  /// tolerances.
  static Velocity coordinate_scale(const Eigen::Ref<const Configuration>& q) {
    return q.cwiseAbs();
  }

  /// Every configuration is valid.
  static void normalize(Eigen::Ref<Configuration>) {}

  static MassBlock mass_block(double mass, Inertia inertia) {
    return Eigen::Vector3d(mass, mass, inertia).asDiagonal();
  }

  /// M v for one body without forming M.
  static Velocity mass_times(double mass, Inertia inertia, const Velocity& v) {
    return {mass * v[0], mass * v[1], inertia * v[2]};
  }

  /// A planar body has no gyroscopic force.
  static Velocity gyroscopic_force(Inertia, const Frame&) { return Velocity::Zero(); }
  static MassBlock gyroscopic_damping(Inertia, const Frame&) { return MassBlock::Zero(); }
};

}  // namespace odyn
