#pragma once
// A body built from parts (a rod and a ball, a wheel and its hub): odyn combines their masses,
// centres and inertias into one rigid body and keeps where the parts are, so that joints and
// forces can be placed on them. Python's add_body(parts=...) is the same (docs/bodies.md).

#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "odyn/core/errors.hpp"
#include "odyn/core/parts.hpp"
#include "odyn/linalg/symmetric_eigenvalues.hpp"
#include "odyn/spatial/body.hpp"

namespace odyn::spatial {

/// A part of a body, placed in the body's *parts frame*: its mass, its inertia about its own
/// centre in its own axes (zero for a point mass, Body::slender_rod for a rod), where that
/// centre is (`at`) and how its axes are turned (`orientation`), both in the parts frame.
struct Part {
  std::string name = {};
  double mass = 0.0;
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// The parts of one body, combined: the total mass, the centre of mass in the parts frame, and
/// the inertia about it in the frame's axes (each part's turned into them, plus Huygens-Steiner
/// for its offset). The body keeps the parts frame's axes; its coordinates have their origin at
/// the combined centre, as every body's do, and `at` turns points into them.
class Composite : public detail::PartsOfBody<Part> {
 public:
  /// Checks each part by name (a unique name; a positive mass; a symmetric, positive
  /// semidefinite inertia meeting the triangle inequality) and combines them.
  Composite(std::string name, std::vector<Part> parts)
      : PartsOfBody(std::move(name), std::move(parts)) {
    for (const Part& p : this->parts()) {
      check_inertia(p);
      const Eigen::Matrix3d turn = p.orientation.normalized().toRotationMatrix();
      const Eigen::Vector3d d = p.at - center_of_mass();
      inertia_ += turn * p.inertia * turn.transpose() +
                  p.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
    }
  }

  /// About the centre of mass, in the parts frame's axes (the body's axes).
  const Eigen::Matrix3d& inertia() const { return inertia_; }

  /// The body whose parts frame starts at `position`, turned by `orientation`, with the parts
  /// frame origin's `linear_velocity` (global) and the `angular_velocity` (body axes).
  Body body(const Eigen::Vector3d& position = Eigen::Vector3d::Zero(),
            const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity(),
            const Eigen::Vector3d& linear_velocity = Eigen::Vector3d::Zero(),
            const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero()) const {
    const Eigen::Matrix3d turn = orientation.normalized().toRotationMatrix();
    return Body{
        .name = name(),
        .mass = mass(),
        .inertia = inertia_,
        .position = position + turn * center_of_mass(),
        .orientation = orientation.normalized(),
        .linear_velocity = linear_velocity + turn * angular_velocity.cross(center_of_mass()),
        .angular_velocity = angular_velocity};
  }

  using PartsOfBody::at;  // a point of the parts frame
  /// Body coordinates of a point given in a part's own frame (its centre and axes).
  Eigen::Vector3d at(std::string_view part, const Eigen::Vector3d& point) const {
    const Part& p = named(part);
    return at(p.at + p.orientation.normalized() * point);
  }

 private:
  void check_inertia(const Part& p) const {
    if (!p.inertia.allFinite() || !p.orientation.coeffs().allFinite() ||
        p.orientation.norm() == 0.0)
      throw ModelError(described(p), "expected a finite inertia and a non-zero orientation");
    if (!p.inertia.isApprox(p.inertia.transpose(), 1e-12))
      throw ModelError(described(p), "the inertia tensor must be symmetric");
    const Eigen::Vector3d moments = symmetric_eigenvalues(p.inertia);  // ascending
    const double scale = std::max(moments[2], 0.0);
    if (moments[0] < -1e-12 * scale || (scale == 0.0 && moments[0] < 0.0))
      throw ModelError(described(p),
                       "principal moments (" + to_text(moments.transpose()) +
                           ") kg m^2: a part's inertia must be positive semidefinite");
    if (moments[2] > moments[0] + moments[1] + 1e-9 * moments.sum())
      throw ModelError(described(p), "principal moments (" + to_text(moments.transpose()) +
                                         ") violate the triangle inequality J3 <= J1 + J2");
  }

  Eigen::Matrix3d inertia_ = Eigen::Matrix3d::Zero();
};

}  // namespace odyn::spatial
