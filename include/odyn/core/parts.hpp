#pragma once
// What a body built from parts is in either space: its parts, checked by name, with their total
// mass and centre of mass. spatial::Composite and planar::Composite add the inertia and the
// body; both derive from PartsOfBody.

#include <cmath>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "odyn/core/errors.hpp"

namespace odyn::detail {

/// The parts of one body (each with a name, a mass and its centre `at` in the body's parts
/// frame): checked (a unique name, a finite mass > 0, a finite centre) and summed.
template <class Part>
class PartsOfBody {
 public:
  using Vector = decltype(Part::at);

  const std::string& name() const { return name_; }
  const std::vector<Part>& parts() const { return parts_; }
  double mass() const { return mass_; }
  /// In the parts frame.
  const Vector& center_of_mass() const { return centre_; }
  /// Body coordinates (origin at the centre of mass) of a point given in the parts frame.
  Vector at(const Vector& point) const { return point - centre_; }

 protected:
  PartsOfBody(std::string name, std::vector<Part> parts)
      : name_(std::move(name)), parts_(std::move(parts)) {
    if (parts_.empty()) throw ModelError(name_, "a body built from parts needs at least one part");
    for (std::size_t i = 0; i < parts_.size(); ++i) {
      const Part& p = parts_[i];
      for (std::size_t j = 0; j < i; ++j)
        if (parts_[j].name == p.name)
          throw ModelError(described(p),
                           "another part has that name; a body's parts need different names");
      if (!(p.mass > 0.0) || !std::isfinite(p.mass))
        throw ModelError(described(p), "expected a finite mass > 0, got " + to_text(p.mass));
      if (!p.at.allFinite())
        throw ModelError(described(p),
                         "expected a finite centre, got " + to_text(p.at.transpose()));
      mass_ += p.mass;
      centre_ += p.mass * p.at;
    }
    centre_ /= mass_;
  }

  /// How errors name a part: "<body> part '<part>'".
  std::string described(const Part& p) const { return name_ + " part '" + p.name + "'"; }

  const Part& named(std::string_view part) const {
    for (const Part& p : parts_)
      if (p.name == part) return p;
    std::string names;
    for (const Part& p : parts_) names += (names.empty() ? "" : ", ") + p.name;
    throw ModelError(name_, "no part named '" + std::string(part) + "'; its parts: " + names);
  }

 private:
  std::string name_;
  std::vector<Part> parts_;
  double mass_ = 0.0;
  Vector centre_ = Vector::Zero();
};

}  // namespace odyn::detail
