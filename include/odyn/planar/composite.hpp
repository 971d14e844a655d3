#pragma once
// A planar body built from parts: the twin of spatial/composite.hpp, with moments of inertia
// about the plane's normal (each part's about its own centre, plus m d^2 for its offset).

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "odyn/core/errors.hpp"
#include "odyn/planar/body.hpp"

namespace odyn::planar {

/// A part of a planar body: its mass, its moment of inertia about its own centre (zero for a
/// point mass) and where that centre is (`at`) in the body's parts frame.
struct Part {
  std::string name = {};
  double mass = 0.0;
  double inertia = 0.0;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
};

/// The parts of one planar body, combined (see odyn::spatial::Composite).
class Composite {
 public:
  /// Checks each part by name (a positive mass, a moment >= 0, a unique name) and combines them.
  Composite(std::string name, std::vector<Part> parts)
      : name_(std::move(name)), parts_(std::move(parts)) {
    if (parts_.empty()) throw ModelError(name_, "a body built from parts needs at least one part");
    for (std::size_t i = 0; i < parts_.size(); ++i) check(i);
    for (const Part& p : parts_) {
      mass_ += p.mass;
      centre_ += p.mass * p.at;
    }
    centre_ /= mass_;
    for (const Part& p : parts_) inertia_ += p.inertia + p.mass * (p.at - centre_).squaredNorm();
  }

  const std::string& name() const { return name_; }
  const std::vector<Part>& parts() const { return parts_; }
  double mass() const { return mass_; }
  /// In the parts frame.
  const Eigen::Vector2d& center_of_mass() const { return centre_; }
  /// About the centre of mass.
  double inertia() const { return inertia_; }

  /// The body whose parts frame starts at `position` and `angle`, with the parts frame origin's
  /// `linear_velocity` and the `angular_velocity`.
  Body body(const Eigen::Vector2d& position = Eigen::Vector2d::Zero(), double angle = 0.0,
            const Eigen::Vector2d& linear_velocity = Eigen::Vector2d::Zero(),
            double angular_velocity = 0.0) const {
    const Eigen::Vector2d offset = Eigen::Rotation2Dd(angle) * centre_;
    return Body{.name = name_,
                .mass = mass_,
                .inertia = inertia_,
                .position = position + offset,
                .angle = angle,
                .linear_velocity =
                    linear_velocity + angular_velocity * Eigen::Vector2d(-offset.y(), offset.x()),
                .angular_velocity = angular_velocity};
  }

  /// Body coordinates of a point given in the parts frame.
  Eigen::Vector2d at(const Eigen::Vector2d& point) const { return point - centre_; }
  /// Body coordinates of a point given relative to a part's centre.
  Eigen::Vector2d at(std::string_view part, const Eigen::Vector2d& point) const {
    for (const Part& p : parts_)
      if (p.name == part) return at(p.at + point);
    std::string names;
    for (const Part& p : parts_) names += (names.empty() ? "" : ", ") + p.name;
    throw ModelError(name_, "no part named '" + std::string(part) + "'; its parts: " + names);
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
    if (!(p.inertia >= 0.0) || !std::isfinite(p.inertia) || !p.at.allFinite())
      throw ModelError(what, "expected a finite moment of inertia >= 0 and a finite centre, got " +
                                 to_text(p.inertia));
  }

  std::string name_;
  std::vector<Part> parts_;
  double mass_ = 0.0;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  double inertia_ = 0.0;
};

}  // namespace odyn::planar
