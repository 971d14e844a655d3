#pragma once
// The recorded state of a stateful element: results keep, at every output time, the discrete
// state a stateful force carries from step to step (a spring's unwrapped angle, an engine's
// stroke count), field by field. The element lists the fields in its description
// (`state_fields`: names, units, docs) and gives their values, in that order, with
//     static std::array<double, K> state_values(const State& state);
// K being the length of the list.

#include <array>
#include <cstddef>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"

namespace odyn {

/// The number of state fields a described element type lists.
template <Described E>
inline constexpr std::size_t num_state_fields = E::description.state_fields.size();

/// Optional: a stateful element whose state results record.
template <class E>
concept RecordsState = Described<E> && Stateful<E> && num_state_fields<E> > 0 &&
                       requires(const typename E::State& state) {
                         {
                           E::state_values(state)
                         } -> std::same_as<std::array<double, num_state_fields<E>>>;
                       };

/// True for a described element that lists state fields but gives no matching state_values (a
/// mistake that would leave its state unrecorded, so front ends refuse it).
template <class E>
concept ListsStateItDoesNotRecord = Described<E> && num_state_fields<E> > 0 && !RecordsState<E>;

}  // namespace odyn
