// odyn._core: planar bodies. Same contract as module.cpp: the Python layer
// (python/odyn/_schema.py) has checked types and shapes. Planar elements are added through the
// catalogue (catalogue.hpp), like spatial ones.

#include <Python.h>

#include <string>
#include <vector>

#include "bindings.hpp"

namespace odyn::python {

namespace {

using Eigen::Vector2d;

Vector2d vec2(const py::dict& d, const char* key) {
  return d[key].cast<Vector2d>();
}

}  // namespace

void add_planar_body(PlanarBox& box, const py::dict& d) {
  if (box.running) throw ModelError("model", "cannot change a model while an analysis runs");
  pl::Body body;
  body.name = text(d, "name");
  body.mass = number(d, "mass");
  body.inertia = number(d, "inertia");
  body.position = vec2(d, "position");
  body.angle = number(d, "angle");
  body.linear_velocity = vec2(d, "linear_velocity");
  body.angular_velocity = number(d, "angular_velocity");
  if (d.contains("velocity_given") && !d["velocity_given"].is_none())
    body.velocity_given = d["velocity_given"].cast<std::array<bool, 3>>();
  box.assembled = {};  // the model changes: assemble again
  box.model.add_body(std::move(body));
}

}  // namespace odyn::python
