// odyn._core: building planar models. Same contract as module.cpp: the Python layer
// (python/odyn/_schema.py) has checked types and shapes, and the dict's keys are the C++
// parameter names of odyn::planar's elements.

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

/// A planar joint frame {point, axis}; an axis left out (None) is the zero vector, which the
/// library reads as "parallel to the other body's axis at the initial pose".
pl::JointFrame planar_joint_frame(const py::dict& d, const char* key) {
  pl::JointFrame out;
  if (!d.contains(key) || d[key].is_none()) return out;
  const py::dict frame = d[key].cast<py::dict>();
  if (frame.contains("point") && !frame["point"].is_none()) out.point = vec2(frame, "point");
  if (frame.contains("axis") && !frame["axis"].is_none()) out.axis = vec2(frame, "axis");
  return out;
}

/// f(t, body) -> Vector (2 numbers) or a number, from a Python callable.
std::function<Vector2d(double, const Planar::Frame&)> vector_function(py::object f,
                                                                      const std::string& what) {
  auto callable = std::make_shared<Callable<Planar>>(std::move(f), 1, what);
  return [callable](double t, const Planar::Frame& frame) {
    const Planar::Frame* frames[1] = {&frame};
    Vector2d value;
    py::gil_scoped_acquire gil;
    read_numbers(callable->call_with_frames(t, frames), value.data(), 2, callable->what());
    return value;
  };
}
std::function<double(double, const Planar::Frame&)> number_function(py::object f,
                                                                    const std::string& what) {
  auto callable = std::make_shared<Callable<Planar>>(std::move(f), 1, what);
  return [callable](double t, const Planar::Frame& frame) {
    const Planar::Frame* frames[1] = {&frame};
    double value = 0.0;
    py::gil_scoped_acquire gil;
    read_numbers(callable->call_with_frames(t, frames), &value, 1, callable->what());
    return value;
  };
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

void add_planar_element(PlanarBox& box, const std::string& type, const py::dict& d) {
  if (box.running) throw ModelError("model", "cannot change a model while an analysis runs");
  box.assembled = {};  // the model changes: assemble again
  PlanarModel& model = box.model;
  const std::string name = text(d, "name");
  const std::string what = type + " '" + name + "'";
  auto body = [&](const char* key) { return model.body(text(d, key)); };
  auto pair = [&]<class Joint>(std::type_identity<Joint>) {
    model.add(Joint(name, body("body_a"), planar_joint_frame(d, "on_a"), body("body_b"),
                    planar_joint_frame(d, "on_b")));
  };
  if (type == "revolute") return pair(std::type_identity<pl::Revolute>{});
  if (type == "translational") return pair(std::type_identity<pl::Translational>{});
  if (type == "fixed") return pair(std::type_identity<pl::Fixed>{});
  if (type == "distance")
    return void(model.add(pl::Distance(name, body("body_a"), vec2(d, "point_a"), body("body_b"),
                                       vec2(d, "point_b"), number(d, "length"))));
  if (type == "revolute_driver")
    return void(model.add(pl::RevoluteDriver(name, body("body_a"), planar_joint_frame(d, "on_a"),
                                             body("body_b"), planar_joint_frame(d, "on_b"),
                                             motion(d, what))));
  if (type == "translational_driver")
    return void(model.add(pl::TranslationalDriver(name, body("body_a"),
                                                  planar_joint_frame(d, "on_a"), body("body_b"),
                                                  planar_joint_frame(d, "on_b"), motion(d, what))));
  if (type == "gravity") return void(model.add(pl::Gravity(name, vec2(d, "acceleration"))));
  if (type == "point_force") {
    if (is_callable(d, "force"))
      return void(model.add(pl::PointForce(name, body("body"), vec2(d, "point"),
                                           vector_function(d["force"], what), axes(d))));
    return void(
        model.add(pl::PointForce(name, body("body"), vec2(d, "point"), vec2(d, "force"), axes(d))));
  }
  if (type == "point_torque") {
    if (is_callable(d, "torque"))
      return void(
          model.add(pl::PointTorque(name, body("body"), number_function(d["torque"], what))));
    return void(model.add(pl::PointTorque(name, body("body"), number(d, "torque"))));
  }
  if (type == "tsda") {
    pl::Tsda::Parameters p{
        number(d, "stiffness"), number(d, "damping"), number(d, "free_length"), {}};
    if (is_callable(d, "actuator"))
      p.actuator = scalar_function3(d["actuator"], what + " actuator");
    return void(model.add(
        pl::Tsda(name, body("body_a"), vec2(d, "point_a"), body("body_b"), vec2(d, "point_b"), p)));
  }
  if (type == "rsda") {
    pl::Rsda::Parameters p{
        number(d, "stiffness"), number(d, "damping"), number(d, "free_angle"), {}};
    if (is_callable(d, "actuator"))
      p.actuator = scalar_function3(d["actuator"], what + " actuator");
    return void(model.add(pl::Rsda(name, body("body_a"), planar_joint_frame(d, "on_a"),
                                   body("body_b"), planar_joint_frame(d, "on_b"), p)));
  }
  if (type == "engine_gas_force") {
    engine::Parameters p;
    p.r = number(d, "r"), p.L = number(d, "L"), p.D = number(d, "D"), p.C = number(d, "C");
    p.p_atm = number(d, "p_atm"), p.kappa = number(d, "kappa"), p.p_comb = number(d, "p_comb");
    return void(model.add(PlanarEngineGasForce(name, body("crank"), body("piston"), p)));
  }
  if (type == "user_force") {
    const auto names = d["bodies"].cast<std::vector<std::string>>();
    auto callable =
        std::make_shared<Callable<Planar>>(d["function"], static_cast<int>(names.size()), what);
    if (names.size() == 1)
      return void(model.add(UserForceT<Planar, 1>(name, {model.body(names[0])}, callable)));
    if (names.size() == 2)
      return void(model.add(
          UserForceT<Planar, 2>(name, {model.body(names[0]), model.body(names[1])}, callable)));
    throw ModelError(name, "a user force acts on one or two bodies");
  }
  throw ModelError(name, "unknown planar element type '" + type + "'");
}

}  // namespace odyn::python
