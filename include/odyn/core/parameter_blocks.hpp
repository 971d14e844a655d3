#pragma once
// Parameter lists that several element descriptions share, in both spaces (see
// description.hpp): planar and spatial twins describe their common parameters once.

#include <array>
#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/ids.hpp"

namespace odyn::parameters {

/// Two bodies and a joint frame on each.
inline constexpr std::array<Parameter, 5> frame_pair{{
    {"name", "name", nullptr, "", "the element's name"},
    {"body_a", "body", nullptr, "", "the first body"},
    {"on_a", "frame", "null", "m", "the joint's frame on body a"},
    {"body_b", "body", nullptr, "", "the second body"},
    {"on_b", "frame", "null", "m", "the joint's frame on body b"},
}};

/// Two bodies and a point on each.
inline constexpr std::array<Parameter, 5> point_pair{{
    {"name", "name", nullptr, "", "the element's name"},
    {"body_a", "body", nullptr, "", "the first body"},
    {"point_a", "vector", "0", "m", "the point on body a, in a's coordinates"},
    {"body_b", "body", nullptr, "", "the second body"},
    {"point_b", "vector", "0", "m", "the point on body b, in b's coordinates"},
}};

/// A distance constraint: two points and the distance they keep.
inline constexpr std::array<Parameter, 6> distance =
    join(point_pair,
         std::array<Parameter, 1>{{{"length", "number", "0", "m",
                                    "the distance kept; <= 0: the distance at the initial pose"}}});

/// An existing joint, or two bodies and their frames: what an element on a joint's coordinates
/// takes (a front end resolves `joint` into the bodies and frames).
inline constexpr std::array<Parameter, 6> joint_or_frame_pair{{
    {"name", "name", nullptr, "", "the element's name"},
    {"joint", "joint", "null", "",
     "the joint whose coordinates the element takes (its bodies and frames are taken); or give "
     "body_a and body_b"},
    {"body_a", "body", "null", "", "the first body (without joint)"},
    {"on_a", "frame", "null", "m", "the joint's frame on body a (without joint)"},
    {"body_b", "body", "null", "", "the second body (without joint)"},
    {"on_b", "frame", "null", "m", "the joint's frame on body b (without joint)"},
}};

/// A driver: an existing joint, or two bodies and their frames; and the motion.
inline constexpr std::array<Parameter, 7> driver{{
    {"name", "name", nullptr, "", "the element's name"},
    {"motion", "motion", nullptr, "m or rad", "the prescribed motion g(t)"},
    {"joint", "joint", "null", "",
     "the joint to drive (its bodies and frames are taken); or give body_a and body_b"},
    {"body_a", "body", "null", "", "the first body (without joint)"},
    {"on_a", "frame", "null", "m", "the joint's frame on body a (without joint)"},
    {"body_b", "body", "null", "", "the second body (without joint)"},
    {"on_b", "frame", "null", "m", "the joint's frame on body b (without joint)"},
}};

/// The joint types whose coordinate a driver or a stop takes with `joint=` (the description's
/// `joints`): a hinge's angle, a slider's slide, and the cylindrical joint's either.
inline constexpr std::array<const char*, 1> revolute_joints{"revolute"};
inline constexpr std::array<const char*, 2> turning_joints{"revolute", "cylindrical"};
inline constexpr std::array<const char*, 1> translational_joints{"translational"};
inline constexpr std::array<const char*, 2> sliding_joints{"translational", "cylindrical"};
inline constexpr std::array<const char*, 1> cylindrical_joints{"cylindrical"};
/// The joint types whose angle or slide a coupler takes, in space and in the plane.
inline constexpr std::array<const char*, 3> coupled_joints{"revolute", "translational",
                                                           "cylindrical"};
inline constexpr std::array<const char*, 2> planar_coupled_joints{"revolute", "translational"};

/// A rotational spring-damper-actuator's law.
inline constexpr std::array<Parameter, 4> rotational_spring{{
    {"stiffness", "number", "0", "N m/rad", "k"},
    {"damping", "number", "0", "N m s/rad", "c"},
    {"free_angle", "number", "0", "rad", "the angle at which the spring exerts no torque"},
    {"actuator", "optional_callable", "null", "N m",
     "actuator(t, theta, theta') -> extra torque on b"},
}};

/// A translational spring-damper-actuator's law.
inline constexpr std::array<Parameter, 4> translational_spring{{
    {"stiffness", "number", "0", "N/m", "k"},
    {"damping", "number", "0", "N s/m", "c"},
    {"free_length", "nonnegative", "0", "m", "the length at which the spring exerts no force"},
    {"actuator", "optional_callable", "null", "N", "actuator(t, L, L') -> extra tension"},
}};

/// A joint's bodies and frames, as a front end passes a turning_joint or sliding_joint
/// parameter (the name of a joint added before, resolved).
template <class Frame>
struct JointReference {
  BodyId body_a;
  Frame on_a;
  BodyId body_b;
  Frame on_b;
};

/// The pair joint (Pair: the space's two-body joint base) that parameter `key` names, under the
/// element's `name` (so that its frames' errors name the element).
template <class Pair, class Frame, class Reader>
Pair pair_joint(Reader& r, const char* key, const std::string& name) {
  const auto joint = parameter<JointReference<Frame>>(r, key);
  return Pair(name, joint.body_a, joint.on_a, joint.body_b, joint.on_b);
}

/// Joint(name, body_a, on_a, body_b, on_b, rest...) from the parameters of frame_pair; Frame is
/// the space's joint frame type.
template <class Joint, class Frame, class Reader, class... Rest>
Joint from_frame_pair(Reader& r, Rest&&... rest) {
  return Joint(parameter<std::string>(r, "name"), parameter<BodyId>(r, "body_a"),
               parameter<Frame>(r, "on_a"), parameter<BodyId>(r, "body_b"),
               parameter<Frame>(r, "on_b"), std::forward<Rest>(rest)...);
}

/// Element(name, body_a, point_a, body_b, point_b, rest...) from the parameters of point_pair;
/// Point is the space's vector type.
template <class Element, class Point, class Reader, class... Rest>
Element from_point_pair(Reader& r, Rest&&... rest) {
  return Element(parameter<std::string>(r, "name"), parameter<BodyId>(r, "body_a"),
                 parameter<Point>(r, "point_a"), parameter<BodyId>(r, "body_b"),
                 parameter<Point>(r, "point_b"), std::forward<Rest>(rest)...);
}

/// A spring-damper-actuator's law {stiffness, damping, free length or angle, actuator} from the
/// parameters of translational_spring or rotational_spring (`free`: which free parameter).
template <class Law, class Reader>
Law spring_law(Reader& r, const char* free) {
  return Law{parameter<double>(r, "stiffness"), parameter<double>(r, "damping"),
             parameter<double>(r, free), parameter<decltype(Law{}.actuator)>(r, "actuator")};
}

}  // namespace odyn::parameters
