#pragma once
// A prescribed motion g(t) with its first two derivatives, for driving constraints.

#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "odyn/core/errors.hpp"

namespace odyn {

struct Motion {
  std::function<double(double)> position;      // g(t)
  std::function<double(double)> velocity;      // g'(t)
  std::function<double(double)> acceleration;  // g''(t)

  /// Throws ModelError naming the driver `element` if a function is missing.
  void require_complete(const std::string& element) const {
    if (!position || !velocity || !acceleration)
      throw ModelError(element,
                       "the motion needs its position, velocity and acceleration functions");
  }

  /// g(t) = start + rate t.
  static Motion constant_velocity(double rate, double start = 0.0) {
    return {[=](double t) { return start + rate * t; }, [=](double) { return rate; },
            [](double) { return 0.0; }};
  }

  /// g(t) = c0 + c1 t + c2 t^2 + ...
  static Motion polynomial(std::vector<double> c) {
    auto eval = [](const std::vector<double>& k, double t) {
      double sum = 0.0;
      for (auto it = k.rbegin(); it != k.rend(); ++it) sum = sum * t + *it;
      return sum;
    };
    auto derive = [](const std::vector<double>& k) {
      std::vector<double> d;
      for (std::size_t i = 1; i < k.size(); ++i) d.push_back(static_cast<double>(i) * k[i]);
      return d;
    };
    std::vector<double> d1 = derive(c), d2 = derive(d1);
    return {[=](double t) { return eval(c, t); }, [=](double t) { return eval(d1, t); },
            [=](double t) { return eval(d2, t); }};
  }

  /// g(t) = offset + amplitude sin(frequency t + phase), frequency in rad/s.
  static Motion harmonic(double amplitude, double frequency, double phase = 0.0,
                         double offset = 0.0) {
    return {[=](double t) { return offset + amplitude * std::sin(frequency * t + phase); },
            [=](double t) { return amplitude * frequency * std::cos(frequency * t + phase); },
            [=](double t) {
              return -amplitude * frequency * frequency * std::sin(frequency * t + phase);
            }};
  }
};

}  // namespace odyn
