#pragma once
// What results report beyond the state and the reactions: every element's own outputs
// (core/outputs.hpp) and the motion of any point on a body, from a workspace at an output time
// (its frames, velocities and accelerations as the analysis left them). Stateful elements' states
// are recorded by their state_values (core/state_fields.hpp).

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "odyn/analysis/system.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/outputs.hpp"
#include "odyn/core/state_fields.hpp"

namespace odyn {

/// The outputs of element `handle` in the workspace's state.
template <class Model, HasOutputs E>
std::array<double, num_outputs<E>> element_outputs(const Model& model, const Workspace<Model>& ws,
                                                   Handle<E> handle) {
  const E& element = model.element(handle);
  const auto& states = std::get<Model::template type_index<E>>(ws.states);
  const auto in = detail::input_of(element, ws.frames, ws.t);
  if constexpr (HasMultiplierOutputs<E>)
    return outputs_of(element, in, states[handle.index],
                      Eigen::Matrix<double, E::num_equations, 1>(
                          ws.lambda.template segment<E::num_equations>(model.row(handle))));
  else
    return outputs_of(element, in, states[handle.index], 0.0);
}

/// One output of the element `name`, by the output's name; throws ModelError naming the
/// element's outputs if it has none of that name.
template <class Model>
double element_output(const Model& model, const Workspace<Model>& ws, std::string_view name,
                      std::string_view output) {
  double value = 0.0;
  bool found = false;
  std::string known;
  const auto where = model.locate(name);
  model.for_each_pool([&]<class E>(const std::vector<E>&, auto type) {
    if (decltype(type)::value != where.type) return;
    if constexpr (HasOutputs<E>) {
      const auto values = element_outputs(model, ws, Handle<E>{where.index});
      for (std::size_t i = 0; i < num_outputs<E>; ++i) {
        const char* listed = E::description.outputs[i].name;
        if (output == listed) value = values[i], found = true;
        known += (i > 0 ? ", " : "") + std::string(listed);
      }
    }
  });
  if (!found)
    throw ModelError(std::string(name), "no output '" + std::string(output) + "'" +
                                            (known.empty() ? "; the element reports none"
                                                           : "; its outputs: " + known));
  return value;
}

/// Position, velocity and acceleration of a body-fixed point, global.
template <class Space>
struct PointMotion {
  typename Space::Vector position, velocity, acceleration;
};

/// The motion of the point `local` (body coordinates) of `body` in the workspace's state.
template <class Model>
PointMotion<typename Model::Space> point_motion([[maybe_unused]] const Model& model,
                                                const Workspace<Model>& ws, BodyId body,
                                                const typename Model::Space::Vector& local) {
  using Space = typename Model::Space;
  const auto& frame = ws.frames[body.index];
  PointMotion<Space> out;
  out.position = frame.point(local);
  out.velocity = frame.point_velocity(local);
  out.acceleration = frame.centripetal(local);
  if (body.index > 0)  // the ground does not move
    out.acceleration += frame.point_jacobian(local) *
                        ws.vdot.template segment<Space::nv>((body.index - 1) * Space::nv);
  return out;
}

}  // namespace odyn
