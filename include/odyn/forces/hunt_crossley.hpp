#pragma once
// The Hunt-Crossley law that contacts (forces/contact.hpp) and joint stops
// (forces/joint_limit.hpp) share: past a surface or a limit by delta, a push
//   F = k delta^n (1 + d delta'),  kept >= 0 (no pull while leaving),
// storing the elastic energy k delta^(n+1) / (n+1).

#include <cmath>
#include <string>

#include "odyn/core/errors.hpp"

namespace odyn {

struct HuntCrossley {
  double stiffness = 0.0;    // k
  double exponent = 1.0;     // n >= 1
  double dissipation = 0.0;  // d >= 0

  /// The push and its derivatives dF/d(delta) and dF/d(delta').
  struct Push {
    double force = 0.0, stiffness = 0.0, damping = 0.0;
  };

  /// At penetration `depth` growing at `depth_rate`; nothing outside (depth <= 0).
  Push at(double depth, double depth_rate) const {
    if (depth <= 0.0) return {};
    const double elastic = stiffness * std::pow(depth, exponent);
    const double force = elastic * (1.0 + dissipation * depth_rate);
    if (force <= 0.0) return {};  // leaving faster than the law pushes: no pull
    return {force, exponent * force / depth, elastic * dissipation};
  }

  /// The elastic energy stored at penetration `depth`.
  double energy(double depth) const {
    return depth > 0.0 ? stiffness * std::pow(depth, exponent + 1.0) / (exponent + 1.0) : 0.0;
  }

  /// Refuses a law that cannot work, naming the element.
  void check(const std::string& name) const {
    if (!(stiffness > 0.0) || !std::isfinite(stiffness))
      throw ModelError(name, "stiffness is " + to_text(stiffness) + "; it must be positive");
    if (!(exponent >= 1.0) || !std::isfinite(exponent))
      throw ModelError(name, "exponent is " + to_text(exponent) +
                                 "; it must be 1 or more (below 1 the stiffness is infinite at "
                                 "first touch)");
    if (!(dissipation >= 0.0) || !std::isfinite(dissipation))
      throw ModelError(name,
                       "dissipation is " + to_text(dissipation) + "; it must be zero or positive");
  }
};

}  // namespace odyn
