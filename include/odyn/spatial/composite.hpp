#pragma once
// A body built from parts (a rod and a ball, a wheel and its hub): odyn combines their masses,
// centres and inertias into one rigid body and keeps where the parts are, so that joints and
// forces can be placed on them. Python's add_body(parts=...) is the same (docs/bodies.md).

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "odyn/core/errors.hpp"
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
class Composite {
 public:
  /// Checks each part by name (a positive mass; a symmetric, positive semidefinite inertia
  /// meeting the triangle inequality; a unique name) and combines them.
  Composite(std::string name, std::vector<Part> parts)
      : name_(std::move(name)), parts_(std::move(parts)) {
    if (parts_.empty()) throw ModelError(name_, "a body built from parts needs at least one part");
    for (std::size_t i = 0; i < parts_.size(); ++i) check(i);
    for (const Part& p : parts_) {
      mass_ += p.mass;
      centre_ += p.mass * p.at;
    }
    centre_ /= mass_;
    for (const Part& p : parts_) {
      const Eigen::Matrix3d turn = p.orientation.normalized().toRotationMatrix();
      const Eigen::Vector3d d = p.at - centre_;
      inertia_ += turn * p.inertia * turn.transpose() +
                  p.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
    }
  }

  const std::string& name() const { return name_; }
  const std::vector<Part>& parts() const { return parts_; }
  double mass() const { return mass_; }
  /// In the parts frame.
  const Eigen::Vector3d& center_of_mass() const { return centre_; }
  /// About the centre of mass, in the parts frame's axes (the body's axes).
  const Eigen::Matrix3d& inertia() const { return inertia_; }

  /// The body whose parts frame starts at `position`, turned by `orientation`, with the parts
  /// frame origin's `linear_velocity` (global) and the `angular_velocity` (body axes).
  Body body(const Eigen::Vector3d& position = Eigen::Vector3d::Zero(),
            const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity(),
            const Eigen::Vector3d& linear_velocity = Eigen::Vector3d::Zero(),
            const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero()) const {
    const Eigen::Matrix3d turn = orientation.normalized().toRotationMatrix();
    return Body{.name = name_,
                .mass = mass_,
                .inertia = inertia_,
                .position = position + turn * centre_,
                .orientation = orientation.normalized(),
                .linear_velocity = linear_velocity + turn * angular_velocity.cross(centre_),
                .angular_velocity = angular_velocity};
  }

  /// Body coordinates of a point given in the parts frame.
  Eigen::Vector3d at(const Eigen::Vector3d& point) const { return point - centre_; }
  /// Body coordinates of a point given in a part's own frame (its centre and axes).
  Eigen::Vector3d at(std::string_view part, const Eigen::Vector3d& point) const {
    const Part& p = named(part);
    return at(p.at + p.orientation.normalized() * point);
  }

 private:
  void check(std::size_t i) const {
    const Part& p = parts_[i];
    const std::string what = name_ + " part '" + p.name + "'";
    for (std::size_t j = 0; j < i; ++j)
      if (parts_[j].name == p.name)
        throw ModelError(what, "another part has that name; a body's parts need different names");
    if (!(p.mass > 0.0) || !std::isfinite(p.mass))
      throw ModelError(what, "expected a finite mass > 0, got " + to_text(p.mass));
    if (!p.inertia.allFinite() || !p.at.allFinite() || !p.orientation.coeffs().allFinite() ||
        p.orientation.norm() == 0.0)
      throw ModelError(what, "expected a finite inertia, centre and non-zero orientation");
    if (!p.inertia.isApprox(p.inertia.transpose(), 1e-12))
      throw ModelError(what, "the inertia tensor must be symmetric");
    const Eigen::Vector3d moments = symmetric_eigenvalues(p.inertia);  // ascending
    const double scale = std::max(moments[2], 0.0);
    if (moments[0] < -1e-12 * scale || (scale == 0.0 && moments[0] < 0.0))
      throw ModelError(what, "principal moments (" + to_text(moments.transpose()) +
                                 ") kg m^2: a part's inertia must be positive semidefinite");
    if (moments[2] > moments[0] + moments[1] + 1e-9 * moments.sum())
      throw ModelError(what, "principal moments (" + to_text(moments.transpose()) +
                                 ") violate the triangle inequality J3 <= J1 + J2");
  }

  const Part& named(std::string_view part) const {
    for (const Part& p : parts_)
      if (p.name == part) return p;
    std::string names;
    for (const Part& p : parts_) names += (names.empty() ? "" : ", ") + p.name;
    throw ModelError(name_, "no part named '" + std::string(part) + "'; its parts: " + names);
  }

  std::string name_;
  std::vector<Part> parts_;
  double mass_ = 0.0;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_ = Eigen::Matrix3d::Zero();
};

}  // namespace odyn::spatial
