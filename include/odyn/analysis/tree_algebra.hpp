#pragma once
// The motion algebra a joint-coordinate tree (analysis/joint_coordinates.hpp) works in, for each
// body space. A motion (twist or acceleration) is (omega, v_centre) and a force (wrench) is
// (torque, force), both in global axes at a body's centre of mass: 6 numbers in space, 3 in the
// plane, where omega and a torque are the one component about the plane's normal. The tree's
// passes are written once over these operations; each space supplies them at its own size, so
// that a planar model costs what a planar model needs.

#include <Eigen/Core>

#include "odyn/core/planar.hpp"
#include "odyn/core/rotation.hpp"
#include "odyn/core/spatial.hpp"
#include "odyn/planar/screw.hpp"
#include "odyn/spatial/screw.hpp"

namespace odyn::detail {

template <class Space>
struct TreeAlgebra;

template <>
struct TreeAlgebra<Spatial> {
  static constexpr int angular = 3;  // omega's (a torque's) components
  static constexpr int linear = 3;   // v's (a force's) components
  static constexpr int size = 6;
  using Angular = Eigen::Vector3d;
  using Linear = Eigen::Vector3d;
  using AngularMatrix = Eigen::Matrix3d;
  using Motion = Eigen::Matrix<double, 6, 1>;
  using MotionMatrix = Eigen::Matrix<double, 6, 6>;
  using Screw = spatial::Screw;

  template <class E>
  static constexpr bool carries_body = spatial::CarriesBody<E>;
  template <class E>
  static constexpr bool screw_joint = spatial::TreeJoint<E>;

  /// A body's axes, turning body-axis angular quantities global.
  static const Eigen::Matrix3d& axes(const Spatial::Frame& frame) { return frame.rotation; }
  /// A body's rotational inertia as a matrix (body axes).
  static const Eigen::Matrix3d& inertia(const Spatial::Inertia& inertia) { return inertia; }

  /// omega x r: the velocity a turn gives a point at r.
  static Linear turn(const Angular& omega, const Linear& r) { return omega.cross(r); }
  /// r x f: the moment of a force at r.
  static Angular moment(const Linear& r, const Linear& force) { return r.cross(force); }

  /// (omega, v) x (omega', v') = (omega x omega', omega x v' + v x omega').
  static Motion motion_cross(const Motion& a, const Motion& b) {
    Motion out;
    out.head<3>() = a.head<3>().cross(b.head<3>());
    out.tail<3>() = a.head<3>().cross(b.tail<3>()) + a.tail<3>().cross(b.head<3>());
    return out;
  }

  /// into += X^T inertia X, the inertia at a child's centre seen at its parent's:
  /// X = [1 0; -[r] 1], r = c_child - c_parent.
  static void add_shifted_inertia(const MotionMatrix& inertia, const Linear& offset,
                                  MotionMatrix& into) {
    const Eigen::Matrix3d arm = skew(offset);
    const Eigen::Matrix3d coupling =
        inertia.topRightCorner<3, 3>() + arm * inertia.bottomRightCorner<3, 3>();
    into.topLeftCorner<3, 3>() += inertia.topLeftCorner<3, 3>() +
                                  arm * inertia.topRightCorner<3, 3>().transpose() - coupling * arm;
    into.topRightCorner<3, 3>() += coupling;
    into.bottomLeftCorner<3, 3>() += coupling.transpose();
    into.bottomRightCorner<3, 3>() += inertia.bottomRightCorner<3, 3>();
  }
};

template <>
struct TreeAlgebra<Planar> {
  static constexpr int angular = 1;
  static constexpr int linear = 2;
  static constexpr int size = 3;
  using Angular = Eigen::Matrix<double, 1, 1>;
  using Linear = Eigen::Vector2d;
  using AngularMatrix = Eigen::Matrix<double, 1, 1>;
  using Motion = Eigen::Vector3d;
  using MotionMatrix = Eigen::Matrix3d;
  using Screw = planar::Screw;

  template <class E>
  static constexpr bool carries_body = planar::CarriesBody<E>;
  template <class E>
  static constexpr bool screw_joint = planar::TreeJoint<E>;

  /// In the plane, body and global angular quantities are the same.
  static AngularMatrix axes(const Planar::Frame&) { return AngularMatrix::Identity(); }
  static AngularMatrix inertia(Planar::Inertia inertia) { return AngularMatrix::Constant(inertia); }

  static Linear turn(const Angular& omega, const Linear& r) {
    return omega[0] * Planar::perpendicular(r);
  }
  static Angular moment(const Linear& r, const Linear& force) {
    return Angular::Constant(Planar::cross(r, force));
  }

  /// (omega, v) x (omega', v') = (0, omega perp(v') - omega' perp(v)).
  static Motion motion_cross(const Motion& a, const Motion& b) {
    Motion out;
    out[0] = 0.0;
    out.tail<2>() =
        a[0] * Planar::perpendicular(b.tail<2>()) - b[0] * Planar::perpendicular(a.tail<2>());
    return out;
  }

  /// into += X^T inertia X with X = [1 0; p 1], p = perp(r) (a child's motion seen at its
  /// parent's centre gains omega perp(r)).
  static void add_shifted_inertia(const MotionMatrix& inertia, const Linear& offset,
                                  MotionMatrix& into) {
    const Linear arm = Planar::perpendicular(offset);
    const Eigen::RowVector2d coupling =
        inertia.topRightCorner<1, 2>() + arm.transpose() * inertia.bottomRightCorner<2, 2>();
    into(0, 0) += inertia(0, 0) + arm.dot(inertia.bottomLeftCorner<2, 1>()) + coupling.dot(arm);
    into.topRightCorner<1, 2>() += coupling;
    into.bottomLeftCorner<2, 1>() += coupling.transpose();
    into.bottomRightCorner<2, 2>() += inertia.bottomRightCorner<2, 2>();
  }
};

}  // namespace odyn::detail
