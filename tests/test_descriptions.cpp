// Element descriptions (odyn/core/description.hpp) against the element types they describe:
// every element of both default catalogues and the engine's gas force builds itself from its
// described parameters, reads each of them (and no other), and takes them where its constructor
// puts them (names, bodies, points, frames).

#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "engine_model.hpp"

namespace test_descriptions {

/// A list of joints (a composite joint's parts). Checked as a concept, so that a type without
/// value_type fails it instead of making the requirement ill-formed (Clang 15).
template <class T>
concept JointList = requires { typename T::value_type; } &&
                    requires(typename T::value_type joint) { joint.on_a, joint.body_b; };

/// A Reader (see description.hpp) that makes up a distinct value for each parameter from its key
/// and the type asked for, and records what was read.
class InventedValues {
 public:
  explicit InventedValues(const odyn::ElementDescription& description)
      : description_(description) {}

  template <class T>
  T get(const char* key) {
    const std::string k = key;
    bool described = false;
    for (const odyn::Parameter& p : description_.parameters) described = described || k == p.name;
    if (!described) throw std::logic_error("reads undescribed parameter " + k);
    read.insert(k);
    if constexpr (std::is_same_v<T, std::string>) {
      return "element " + k;
    } else if constexpr (std::is_same_v<T, double>) {
      // The gas force needs C > 1 and L > r, a contact law an exponent of 1 or more.
      return k == "C" ? 9.0 : k == "L" ? 0.5 : k == "exponent" ? 1.5 : 0.25;
    } else if constexpr (std::is_same_v<T, std::optional<double>>) {
      return k == "lower" ? -0.25 : 0.25;  // a stop's limits, lower below upper
    } else if constexpr (std::is_same_v<T, odyn::JointCoordinateKind> ||
                         std::is_same_v<T, std::optional<odyn::JointCoordinateKind>>) {
      return odyn::JointCoordinateKind::angle;  // a coupler's coordinates
    } else if constexpr (JointList<T>) {
      return typename T::value_type{odyn::BodyId{2}, {}, odyn::BodyId{3}, {}};  // joint_3
    } else if constexpr (std::is_same_v<T, odyn::BodyId>) {
      return odyn::BodyId{k == "body_b" || k == "piston" ? 2 : 1};
    } else if constexpr (std::is_same_v<T, odyn::Axes>) {
      return odyn::Axes::global;
    } else if constexpr (std::is_same_v<T, odyn::Motion>) {
      return odyn::Motion::constant_velocity(1.0, 0.0);
    } else if constexpr (std::is_same_v<T, odyn::spatial::JointFrame>) {
      odyn::spatial::JointFrame frame;
      frame.point = k == "on_a" ? Eigen::Vector3d(0.1, 0.2, 0.3) : Eigen::Vector3d(-0.3, 0.0, 0.4);
      frame.axis = Eigen::Vector3d(0.0, 0.0, 1.0);
      return frame;
    } else if constexpr (std::is_same_v<T, odyn::planar::JointFrame>) {
      odyn::planar::JointFrame frame;
      frame.point = k == "on_a" ? Eigen::Vector2d(0.1, 0.2) : Eigen::Vector2d(-0.3, 0.4);
      return frame;
    } else if constexpr (requires(T joint) { joint.on_a, joint.body_b; }) {
      // A joint a gear, a rack or a coupler names: bodies 1 and 2 for the first, 1 and 3 for
      // the second.
      const bool first = k == "joint_a" || k == "pinion" || k == "joint_1";
      return T{odyn::BodyId{1}, {}, odyn::BodyId{first ? 2 : 3}, {}};
    } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
      return k == "point_b" ? Eigen::Vector3d(-0.3, 0.0, 0.4) : Eigen::Vector3d(0.1, 0.2, 0.3);
    } else if constexpr (std::is_same_v<T, Eigen::Vector2d>) {
      return k == "point_b" ? Eigen::Vector2d(-0.3, 0.4) : Eigen::Vector2d(0.1, 0.2);
    } else if constexpr (std::is_same_v<T, Eigen::Matrix<double, 1, 1>>) {
      return Eigen::Matrix<double, 1, 1>(0.5);
    } else if constexpr (requires { T::Identity(); }) {
      return T::Identity();  // a bushing's stiffness and damping, a 6-vector preload
    } else {
      return T{};  // functions: none (the elements take constants or no actuator then)
    }
  }
  bool is_function(const char*) const { return false; }

  std::set<std::string> read;

 private:
  const odyn::ElementDescription& description_;
};

/// The parameters a front end hands to from_parameters: all but the `joint` of an element that
/// takes a joint's bodies and frames (a driver, a stop), which it resolves into them. An element
/// that sits on the joint itself (friction) reads the joint's name.
std::set<std::string> handed_over(const odyn::ElementDescription& description) {
  bool takes_frames = false;
  for (const odyn::Parameter& p : description.parameters)
    takes_frames = takes_frames || std::string(p.name) == "body_a";
  std::set<std::string> out;
  for (const odyn::Parameter& p : description.parameters)
    if (!takes_frames || std::string(p.name) != "joint") out.insert(p.name);
  return out;
}

template <class E>
void check_description() {
  static_assert(odyn::Described<E>);
  static_assert(odyn::is_well_formed(E::description));
  static_assert(!odyn::ListsOutputsItDoesNotCompute<E>);
  static_assert(!odyn::ListsStateItDoesNotRecord<E>);
  const odyn::ElementDescription& d = E::description;
  INFO(d.type);
  InventedValues values(d);
  E element = E::from_parameters(values);
  if constexpr (odyn::OnJoint<E>) {
    // It takes its bodies from its joint when a model adds it: a hinge between bodies 1 and 2.
    using Space = typename E::Space;
    using Revolute = std::conditional_t<std::is_same_v<Space, odyn::Spatial>,
                                        odyn::spatial::Revolute, odyn::planar::Revolute>;
    CHECK(element.joint_name() == "element joint");
    element.attach(Revolute("hinge", odyn::BodyId{1}, {}, odyn::BodyId{2}, {}), 0, 0);
  }
  CHECK(values.read == handed_over(d));
  CHECK(element.name() == "element name");
  const std::string category = d.category;
  CHECK((category == "joint" || category == "driver" || category == "force"));
  for (const odyn::Parameter& p : d.parameters) {
    INFO(p.name);
    CHECK(std::string(p.doc).size() > 0);
  }
  for (const auto& list : {d.outputs, d.state_fields})
    for (const odyn::Output& o : list) {
      INFO(o.name);
      CHECK(std::string(o.doc).size() > 0);
    }
  if constexpr (requires { element.bodies(); }) {
    // Bodies in the described order: body_a (or crank) is 1, body_b (or piston) is 2.
    const auto& bodies = element.bodies();
    CHECK(bodies[0].index == 1);
    if constexpr (std::tuple_size_v<std::remove_cvref_t<decltype(bodies)>> == 2)
      CHECK(bodies[1].index == 2);
  }
}

template <class Catalogue>
struct EachElement;
template <class Body, class... Elements>
struct EachElement<odyn::Model<Body, Elements...>> {
  static void check() {
    (check_description<Elements>(), ...);
    // Type names are unique within a space.
    const std::set<std::string> names{Elements::description.type...};
    CHECK(names.size() == sizeof...(Elements));
  }
};

TEST_CASE("Every element builds itself from the parameters its description lists",
          "[descriptions]") {
  EachElement<odyn::spatial::DefaultModel>::check();
  EachElement<odyn::planar::DefaultModel>::check();
  check_description<engine::GasForce>();
  check_description<engine::planar::GasForce>();
}

TEST_CASE("Described parameters reach the element's constructor", "[descriptions]") {
  // Points and frames land on the side they name (a swap would pass the test above).
  {
    InventedValues values(odyn::spatial::Revolute::description);
    const auto joint = odyn::spatial::Revolute::from_parameters(values);
    CHECK(joint.frame(0).point.isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
    CHECK(joint.frame(1).point.isApprox(Eigen::Vector3d(-0.3, 0.0, 0.4)));
  }
  {
    InventedValues values(odyn::planar::Distance::description);
    const auto rod = odyn::planar::Distance::from_parameters(values);
    CHECK(rod.frame(0).point.isApprox(Eigen::Vector2d(0.1, 0.2)));
    CHECK(rod.frame(1).point.isApprox(Eigen::Vector2d(-0.3, 0.4)));
    CHECK(rod.length() == 0.25);
  }
  // A parameter list's shared blocks keep their order: the pair first, the law after.
  const auto& tsda = odyn::spatial::Tsda::description.parameters;
  REQUIRE(tsda.size() == 9);
  CHECK(std::string(tsda[0].name) == "name");
  CHECK(std::string(tsda[4].name) == "point_b");
  CHECK(std::string(tsda[8].name) == "actuator");
  // Planar torques are numbers and have no axes; spatial ones have both.
  CHECK(odyn::planar::PointTorque::description.parameters.size() == 3);
  CHECK(odyn::spatial::PointTorque::description.parameters.size() == 4);
}

}  // namespace test_descriptions
