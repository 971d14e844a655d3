#pragma once
// Where a joint sits on a body: a point and an axis in body coordinates, and optionally a
// reference direction perpendicular to the axis (the zero of the joint's angle).

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "odyn/core/errors.hpp"
#include "odyn/core/rotation.hpp"
#include "odyn/core/spatial.hpp"

namespace odyn::spatial {

/// A joint's point and axes on one body, as the user gives them (body coordinates).
struct JointFrame {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  /// Zero vector: chosen from the other body's reference at the initial pose. To leave it out,
  /// leave the member out ({point, axis}): an Eigen vector written {} is uninitialized.
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
};

/// A joint frame made orthonormal: w along the axis, u the reference, v = w x u.
struct Triad {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d v = Eigen::Vector3d::UnitY();
  Eigen::Vector3d w = Eigen::Vector3d::UnitZ();
  bool reference_given = false;

  /// Checks the user's axes (naming the joint and body side on error) and normalizes them.
  static Triad from(const JointFrame& frame, const std::string& joint, const char* side) {
    if (!frame.point.allFinite())
      throw ModelError(joint, std::string("point on body ") + side + " is not finite");
    const double length = frame.axis.norm();
    if (!(length > 1e-12) || !std::isfinite(length))
      throw ModelError(joint, std::string("axis on body ") + side +
                                  " must be a non-zero finite vector, got (" +
                                  to_text(frame.axis.transpose()) + ")");
    Triad triad;
    triad.point = frame.point;
    triad.w = frame.axis / length;
    triad.reference_given = frame.reference.squaredNorm() > 0.0;
    if (triad.reference_given) {
      const Eigen::Vector3d across = frame.reference - frame.reference.dot(triad.w) * triad.w;
      if (!(across.norm() > 1e-9 * frame.reference.norm()))
        throw ModelError(joint, std::string("reference direction on body ") + side +
                                    " is parallel to its axis; give one perpendicular to it");
      triad.u = across.normalized();
    } else {
      triad.u = any_perpendicular(triad.w);
    }
    triad.v = triad.w.cross(triad.u);
    return triad;
  }

  /// If this side's reference was not given, takes the other side's reference direction at the
  /// initial pose, so that the joint's angle starts at zero.
  void adopt_reference(const Eigen::Vector3d& global_reference,
                       const Spatial::RotationMatrix& rotation) {
    if (reference_given) return;
    Eigen::Vector3d local = rotation.transpose() * global_reference;
    local -= local.dot(w) * w;
    if (local.norm() > 1e-6) u = local.normalized();
    v = w.cross(u);
  }
};

/// Makes a pair of triads for a joint between bodies a and b and aligns their references.
inline void bind_references(Triad& on_a, Triad& on_b, const Spatial::Frame& a,
                            const Spatial::Frame& b) {
  if (on_a.reference_given || !on_b.reference_given)
    on_b.adopt_reference(a.rotation * on_a.u, b.rotation);
  else
    on_a.adopt_reference(b.rotation * on_b.u, a.rotation);
}

}  // namespace odyn::spatial
