#pragma once
// A planar body built from parts: the twin of spatial/composite.hpp, with moments of inertia
// about the plane's normal (each part's about its own centre, plus m d^2 for its offset).

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "odyn/core/errors.hpp"
#include "odyn/core/parts.hpp"
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
class Composite : public detail::PartsOfBody<Part> {
 public:
  /// Checks each part by name (a unique name, a positive mass, a moment >= 0) and combines them.
  Composite(std::string name, std::vector<Part> parts)
      : PartsOfBody(std::move(name), std::move(parts)) {
    for (const Part& p : this->parts()) {
      if (!(p.inertia >= 0.0) || !std::isfinite(p.inertia))
        throw ModelError(described(p),
                         "expected a finite moment of inertia >= 0, got " + to_text(p.inertia));
      inertia_ += p.inertia + p.mass * (p.at - center_of_mass()).squaredNorm();
    }
  }

  /// About the centre of mass.
  double inertia() const { return inertia_; }

  /// The body whose parts frame starts at `position` and `angle`, with the parts frame origin's
  /// `linear_velocity` and the `angular_velocity`.
  Body body(const Eigen::Vector2d& position = Eigen::Vector2d::Zero(), double angle = 0.0,
            const Eigen::Vector2d& linear_velocity = Eigen::Vector2d::Zero(),
            double angular_velocity = 0.0) const {
    const Eigen::Vector2d offset = Eigen::Rotation2Dd(angle) * center_of_mass();
    return Body{.name = name(),
                .mass = mass(),
                .inertia = inertia_,
                .position = position + offset,
                .angle = angle,
                .linear_velocity =
                    linear_velocity + angular_velocity * Eigen::Vector2d(-offset.y(), offset.x()),
                .angular_velocity = angular_velocity};
  }

  using PartsOfBody::at;  // a point of the parts frame
  /// Body coordinates of a point given relative to a part's centre.
  Eigen::Vector2d at(std::string_view part, const Eigen::Vector2d& point) const {
    return at(named(part).at + point);
  }

 private:
  double inertia_ = 0.0;
};

}  // namespace odyn::planar
