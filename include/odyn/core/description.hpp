#pragma once
// How an element type describes its parameters once, for every front end: names, kinds, units,
// defaults and one-line docs. The Python methods, the scene-file schema, the checks of unknown
// keys and the documentation's element table all come from this one description.
//
// A described element type E offers
//     static constexpr ElementDescription description{...};
//     template <class Reader> static E from_parameters(Reader& reader);
// where from_parameters builds E from its parameters, each read as the C++ type its constructor
// takes: parameter<T>(reader, "key"). A Reader (the Python bindings' dict reader is one) turns
// its source's values into those types and knows which keys were read.

#include <array>
#include <concepts>
#include <cstddef>
#include <span>

namespace odyn {

/// One parameter of an element.
struct Parameter {
  const char* name;      // as the constructor, Python and scene files call it
  const char* kind;      // the values it takes: one of parameter_kinds
  const char* fallback;  // its default as JSON text; nullptr: required
  const char* unit;      // SI unit; "" for none
  const char* doc;       // one line
};

/// One named output an element reports (core/outputs.hpp), as ADAMS's requests do, or one
/// field of a stateful element's recorded state (core/state_fields.hpp).
struct Output {
  const char* name;  // as results, scene files and CSV columns call it
  const char* unit;  // SI unit; "" for none
  const char* doc;   // one line
};

/// What an element type tells the front ends about itself.
struct ElementDescription {
  const char* type;      // its name in Python and scene files, "revolute"; unique in a space
  const char* category;  // "joint", "driver" or "force"
  const char* summary;   // one line: what it does (and its number of equations)
  std::span<const Parameter> parameters;
  std::span<const Output> outputs = {};  // what outputs(in) returns, in order
  std::span<const Output> state_fields = {};  // what state_values(state) returns, in order
  std::span<const char* const> joints = {};   // the joint types a `joint` parameter may name
};

/// A kind of parameter value, and how it reads in each space.
struct ParameterKind {
  const char* name;
  const char* doc;
};

/// Every kind a description may use. A vector's, a wrench's or a matrix's default 0 is zero.
inline constexpr std::array<ParameterKind, 26> parameter_kinds{{
    {"name", "a name, unique among the model's bodies and elements"},
    {"body", "a body's name (\"ground\" for the ground)"},
    {"bodies", "a list of one or two body names"},
    {"joint", "the name of a joint added before"},
    {"turning_joint",
     "the name of a revolute or cylindrical joint added before (in the plane: a revolute joint), "
     "whose angle the element takes"},
    {"sliding_joint",
     "the name of a translational or cylindrical joint added before (in the plane: a "
     "translational joint), whose slide the element takes"},
    {"coupled_joint",
     "the name of a revolute, translational or cylindrical joint added before (in the plane: a "
     "revolute or translational joint), whose angle or slide the element takes"},
    {"optional_coupled_joint", "a coupled_joint, or null for none"},
    {"coordinate",
     "\"angle\" or \"slide\": which coordinate of a joint; null: the joint's own (a "
     "revolute's angle, a translational joint's slide)"},
    {"vector", "3 numbers in space, 2 in the plane"},
    {"frame",
     "a joint frame on a body, in body coordinates: {point, axis, reference} in space (left out: "
     "the origin, the z axis, a reference chosen from the other body's), {point, axis} in the "
     "plane (an axis left out is the other body's at the initial pose)"},
    {"number", "a finite number"},
    {"optional_number", "a finite number, or null for none"},
    {"flag", "true or false"},
    {"nonnegative", "a finite number >= 0"},
    {"positive", "a finite number > 0"},
    {"axes", "\"global\" or \"body\": the axes a vector is given in"},
    {"motion", "a motion g(t): constant_velocity, polynomial, harmonic or three functions"},
    {"vector_or_callable", "a constant vector, or a function f(t, body) returning one"},
    {"angular_or_callable",
     "a constant torque (3 numbers in space, 1 in the plane), or a function f(t, body) "
     "returning one"},
    {"optional_callable", "a function f(t, x, x') returning a number, or null for none"},
    {"callable", "a Python function"},
    {"optional_function", "a Python function, or null for none"},
    {"wrench",
     "a force then a torque, in the element's axes: 6 numbers in space, 3 in the plane (fx, fy, "
     "torque)"},
    {"component_matrix",
     "a symmetric positive semidefinite matrix over a wrench's components: 6 x 6 in space, 3 x 3 "
     "in the plane, or a list of its diagonal"},
    {"wrench_law",
     "a function f(t, x, x') of a displacement and its rate (6 numbers each in space, 3 in the "
     "plane) returning a wrench, or null for none"},
}};

/// True if a kind of that name is in parameter_kinds.
constexpr bool is_parameter_kind(const char* kind) {
  for (const ParameterKind& known : parameter_kinds) {
    const char *a = known.name, *b = kind;
    while (*a != '\0' && *a == *b) ++a, ++b;
    if (*a == *b) return true;
  }
  return false;
}

/// Joins parameter lists: shared blocks (a pair of bodies and frames) plus an element's own.
template <std::size_t N, std::size_t M>
constexpr std::array<Parameter, N + M> join(const std::array<Parameter, N>& first,
                                            const std::array<Parameter, M>& second) {
  std::array<Parameter, N + M> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = first[i];
  for (std::size_t i = 0; i < M; ++i) out[N + i] = second[i];
  return out;
}

/// True if every parameter of the description has a known kind and a unique name, a `joint`
/// parameter comes with the joint types it may name, and every output and state field has a
/// unique name.
constexpr bool is_well_formed(const ElementDescription& description) {
  const auto same = [](const char* a, const char* b) {
    while (*a != '\0' && *a == *b) ++a, ++b;
    return *a == *b;
  };
  for (std::size_t i = 0; i < description.parameters.size(); ++i) {
    if (!is_parameter_kind(description.parameters[i].kind)) return false;
    if (same(description.parameters[i].kind, "joint") && description.joints.empty()) return false;
    for (std::size_t j = 0; j < i; ++j)
      if (same(description.parameters[i].name, description.parameters[j].name)) return false;
  }
  for (const auto& list : {description.outputs, description.state_fields})
    for (std::size_t i = 0; i < list.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (same(list[i].name, list[j].name)) return false;
  return true;
}

/// An element type that describes itself (see the top of this header).
template <class E>
concept Described = requires {
  { E::description } -> std::convertible_to<const ElementDescription&>;
};

/// The parameter `key` as type T, from a Reader inside from_parameters.
template <class T, class Reader>
T parameter(Reader& reader, const char* key) {
  return reader.template get<T>(key);
}

/// True if the parameter `key` was given as a function rather than as a value.
template <class Reader>
bool parameter_is_function(Reader& reader, const char* key) {
  return reader.is_function(key);
}

}  // namespace odyn
