#pragma once
// Element outputs, as ADAMS's requests: what an element reports about itself at any state (a
// spring's length, rate and tension; a bushing's displacement, rate and force components). An
// element type with outputs lists them in its description (`outputs`: names, units, docs) and
// computes them, in that order, with
//     std::array<double, K> outputs(const Input& in) const;                    or, stateful:
//     std::array<double, K> outputs(const Input& in, const State& state) const;
// where K is the length of the description's list; a constraint may also read its multipliers
// (HasMultiplierOutputs). Results record them at every output time.

#include <Eigen/Core>
#include <array>
#include <cstddef>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"

namespace odyn {

/// The number of outputs a described element type lists.
template <Described E>
inline constexpr std::size_t num_outputs = E::description.outputs.size();

template <class E>
concept HasStatelessOutputs = Described<E> && requires(const E& e, const InputOf<E>& in) {
  { e.outputs(in) } -> std::same_as<std::array<double, num_outputs<E>>>;
};

template <class E>
concept HasStatefulOutputs =
    Described<E> && Stateful<E> &&
    requires(const E& e, const InputOf<E>& in, const typename E::State& state) {
      { e.outputs(in, state) } -> std::same_as<std::array<double, num_outputs<E>>>;
    };

/// A constraint whose outputs also read its multipliers (a gear's mesh torque):
///     std::array<double, K> outputs(const Input& in, const State& state,
///                                   const Eigen::Matrix<double, M, 1>& lambda) const;
template <class E>
concept HasMultiplierOutputs =
    Described<E> && StatefulConstraint<E> &&
    requires(const E& e, const InputOf<E>& in, const typename E::State& state,
             const Eigen::Matrix<double, E::num_equations, 1>& lambda) {
      { e.outputs(in, state, lambda) } -> std::same_as<std::array<double, num_outputs<E>>>;
    };

/// Optional: an element that reports outputs.
template <class E>
concept HasOutputs = (HasStatelessOutputs<E> || HasStatefulOutputs<E> || HasMultiplierOutputs<E>) &&
                     num_outputs<E> > 0;

/// True for a described element whose outputs() does not match its listed outputs (missing, or
/// of another length): a mistake that would leave its outputs unrecorded, so front ends refuse it.
template <class E>
concept ListsOutputsItDoesNotCompute = Described<E> && num_outputs<E> > 0 && !HasOutputs<E>;

/// The element's outputs at `in` (`state` is read by a stateful element only, `lambda`, its
/// multipliers, by one with HasMultiplierOutputs only).
template <HasOutputs E, class Multipliers>
std::array<double, num_outputs<E>> outputs_of(const E& element, const InputOf<E>& in,
                                              const StateOf<E>& state, const Multipliers& lambda) {
  if constexpr (HasMultiplierOutputs<E>)
    return element.outputs(in, state, lambda);
  else if constexpr (HasStatefulOutputs<E>)
    return element.outputs(in, state);
  else
    return element.outputs(in);
}

}  // namespace odyn
