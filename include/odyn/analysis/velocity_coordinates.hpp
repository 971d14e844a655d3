#pragma once
// What each velocity coordinate of an analysis is, so that a report can name it: a body's
// translation or turn in absolute coordinates, a joint's angle or travel in joint coordinates.

#include <string>

namespace odyn {

struct VelocityCoordinate {
  std::string element;    // the body (absolute coordinates) or the tree joint (joint ones)
  std::string component;  // "x", "rz", "angle", "travel 2", ...
  bool angular = false;   // a turn (rad) rather than a travel (m)
  std::string text() const { return element + "." + component; }
};

}  // namespace odyn
