#pragma once
// odyn._core.combined_body: a body built from parts (odyn.composite) combined by the library's
// spatial::Composite or planar::Composite, for every model whatever module compiles it.

#include <odyn/python/dict_values.hpp>
#include <odyn/python/models.hpp>

#include <string>
#include <vector>

namespace odyn::python {

/// The body dict the Python layer checked, with its "parts", in `space` ("spatial" or
/// "planar"): the body as a model takes it (the
/// combined mass and inertia; the position and linear velocity of the centre of mass, where the
/// given ones are the parts frame's) and the "center_of_mass" in the parts frame.
inline py::dict combined_body(const py::dict& body, const std::string& space) {
  py::dict out;
  for (auto [key, value] : body)
    if (key.cast<std::string>() != "parts") out[key] = value;
  const std::string name = text(body, "name");
  if (space == "planar") {
    std::vector<pl::Part> parts;
    for (py::handle item : body["parts"]) {
      const auto part = item.cast<py::dict>();
      parts.push_back({.name = text(part, "name"),
                       .mass = number(part, "mass"),
                       .inertia = number(part, "inertia"),
                       .at = part["at"].cast<Eigen::Vector2d>()});
    }
    const pl::Composite combined(name, std::move(parts));
    const pl::Body b = combined.body(
        body["position"].cast<Eigen::Vector2d>(), number(body, "angle"),
        body["linear_velocity"].cast<Eigen::Vector2d>(), number(body, "angular_velocity"));
    out["mass"] = b.mass;
    out["inertia"] = b.inertia;
    out["position"] = std::vector<double>{b.position.x(), b.position.y()};
    out["linear_velocity"] = std::vector<double>{b.linear_velocity.x(), b.linear_velocity.y()};
    out["center_of_mass"] =
        std::vector<double>{combined.center_of_mass().x(), combined.center_of_mass().y()};
    return out;
  }
  const auto quaternion = [](py::handle q) {  // w, x, y, z
    const auto v = q.cast<Eigen::Vector4d>();
    return Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
  };
  const auto list = [](const Eigen::Vector3d& v) { return std::vector<double>{v[0], v[1], v[2]}; };
  std::vector<sp::Part> parts;
  for (py::handle item : body["parts"]) {
    const auto part = item.cast<py::dict>();
    parts.push_back({.name = text(part, "name"),
                     .mass = number(part, "mass"),
                     .inertia = part["inertia"].cast<Eigen::Matrix3d>(),
                     .at = part["at"].cast<Eigen::Vector3d>(),
                     .orientation = quaternion(part["orientation"])});
  }
  const sp::Composite combined(name, std::move(parts));
  const sp::Body b =
      combined.body(body["position"].cast<Eigen::Vector3d>(), quaternion(body["orientation"]),
                    body["linear_velocity"].cast<Eigen::Vector3d>(),
                    body["angular_velocity"].cast<Eigen::Vector3d>());
  out["mass"] = b.mass;
  std::vector<std::vector<double>> inertia;
  for (int i = 0; i < 3; ++i) inertia.push_back(list(b.inertia.row(i).transpose()));
  out["inertia"] = inertia;
  out["position"] = list(b.position);
  out["linear_velocity"] = list(b.linear_velocity);
  out["center_of_mass"] = list(combined.center_of_mass());
  return out;
}

}  // namespace odyn::python
