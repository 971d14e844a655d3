#pragma once
// Identifiers of bodies and elements inside a model.

#include <compare>
#include <cstddef>

namespace odyn {

/// A body of a model. Index 0 is the ground, which has no coordinates.
struct BodyId {
  int index = 0;
  bool is_ground() const { return index == 0; }
  auto operator<=>(const BodyId&) const = default;
};

inline constexpr BodyId ground{0};

/// A typed handle to an element of type E in a model: its position in E's pool.
template <class E>
struct Handle {
  std::size_t index = 0;
};

}  // namespace odyn
