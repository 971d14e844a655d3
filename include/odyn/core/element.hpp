#pragma once
// What an element reads and writes, and the concepts that say what an element type must provide.
//
// A constraint element with m equations between NB bodies fills, from its bodies' frames:
//   phi      (m)        Phi(q, t)
//   jacobian (m x nv)   one block per body: d(Phi-dot)/d(body velocity), i.e. Phi_q
//   phi_t    (m)        dPhi/dt
// and on request gamma (m), the acceleration right-hand side: Phi_q v' = gamma.
// A force element fills its bodies' generalized forces Q and, if it has them, the blocks
// -dQ/dq and -dQ/dv that make the Newton matrix of implicit integrators exact.

#include <Eigen/Core>
#include <array>
#include <concepts>
#include <cstddef>
#include <string>
#include <utility>

#include "odyn/core/ids.hpp"

namespace odyn {

/// The frames of an element's bodies (in the order of its `bodies()`) and the time.
template <class Space, int NB>
struct ElementInput {
  std::array<const typename Space::Frame*, NB> frames;
  double t = 0.0;
  const typename Space::Frame& body(int i) const { return *frames[i]; }
};

template <class Space, int M, int NB>
struct ConstraintBlocks {
  Eigen::Matrix<double, M, 1> phi;                               // (m)
  Eigen::Matrix<double, M, 1> phi_t;                             // (m)
  std::array<Eigen::Matrix<double, M, Space::nv>, NB> jacobian;  // NB x (m x nv)
};

template <class Space, int NB>
struct ForceBlocks {
  static constexpr int size = NB * Space::nv;
  std::array<typename Space::Velocity, NB> force;  // generalized force on each body
  Eigen::Matrix<double, size, size> stiffness;     // -dQ/dq over the element's bodies
  Eigen::Matrix<double, size, size> damping;       // -dQ/dv over the element's bodies
};

template <class E>
using InputOf = ElementInput<typename E::Space, E::num_bodies>;

template <class E>
concept NamedElement = requires(const E& e) {
  typename E::Space;
  { E::num_bodies } -> std::convertible_to<int>;
  { e.name() } -> std::convertible_to<std::string>;
  { e.bodies() } -> std::same_as<const std::array<BodyId, E::num_bodies>&>;
};

/// A kinematic constraint that needs no memory of the past: joints and drivers.
template <class E>
concept StatelessConstraint =
    NamedElement<E> &&
    requires(const E& e, const InputOf<E>& in,
             ConstraintBlocks<typename E::Space, E::num_equations, E::num_bodies>& out) {
      { E::num_equations } -> std::convertible_to<int>;
      e.evaluate(in, out);
      { e.gamma(in) } -> std::convertible_to<Eigen::Matrix<double, E::num_equations, 1>>;
    };

/// A constraint with a discrete state, kept and advanced as a stateful force's is: a gear pair
/// between two spatial hinges, whose equation needs each angle's whole turns.
template <class E>
concept StatefulConstraint =
    NamedElement<E> &&
    requires(const E& e, const InputOf<E>& in, typename E::State& state,
             ConstraintBlocks<typename E::Space, E::num_equations, E::num_bodies>& out) {
      { E::num_equations } -> std::convertible_to<int>;
      { e.initial_state(in) } -> std::same_as<typename E::State>;
      e.evaluate(in, std::as_const(state), out);
      {
        e.gamma(in, std::as_const(state))
      } -> std::convertible_to<Eigen::Matrix<double, E::num_equations, 1>>;
      e.advance(in, state);
    };

/// A kinematic constraint: joints, drivers and couplings.
template <class E>
concept Constraint = StatelessConstraint<E> || StatefulConstraint<E>;

template <class E>
using BlocksOf = ConstraintBlocks<typename E::Space, E::num_equations, E::num_bodies>;

template <class E>
using ForceBlocksOf = ForceBlocks<typename E::Space, E::num_bodies>;

/// A force element that needs no memory of the past.
template <class E>
concept StatelessForce = NamedElement<E> &&
    requires(const E& e, const InputOf<E>& in, ForceBlocksOf<E>& out) {
  e.evaluate(in, out);
};

/// A force element with a discrete state (for example a revolution counter). The state lives
/// in the workspace, is read during a step and advanced once the step is accepted.
template <class E>
concept StatefulForce = NamedElement<E> &&
    requires(const E& e, const InputOf<E>& in, typename E::State& state, ForceBlocksOf<E>& out) {
  { e.initial_state(in) } -> std::same_as<typename E::State>;
  e.evaluate(in, std::as_const(state), out);
  e.advance(in, state);
};

template <class E>
concept ForceElement = StatelessForce<E> || StatefulForce<E>;

/// An element, force or constraint, whose discrete state the workspace keeps.
template <class E>
concept Stateful = StatefulForce<E> || StatefulConstraint<E>;

/// Optional: a stateful force whose law switches abruptly (a valve opening, a contact closing).
/// event_function(in, state) is negative before the next switch and reaches zero at it. The
/// force keeps the law its state names for the whole step, so the integrator ends a step
/// exactly at the switch; advance() then moves the state to the next law.
template <class E>
concept HasEvents = StatefulForce<E> &&
    requires(const E& e, const InputOf<E>& in, const typename E::State& state) {
  { e.event_function(in, state) } -> std::convertible_to<double>;
};

/// A force that acts on every body alike, such as gravity.
template <class E>
concept FieldForce = requires(const E& e, double mass, const typename E::Space::Frame& frame) {
  typename E::Space;
  { e.name() } -> std::convertible_to<std::string>;
  { e.force_on(mass, frame) } -> std::same_as<typename E::Space::Velocity>;
  { e.potential_energy(mass, frame) } -> std::convertible_to<double>;
};

template <class E>
concept Element = Constraint<E> || ForceElement<E> || FieldForce<E>;

/// Optional: a force element that fills `stiffness` and `damping` in `jacobians(in, out)`, or
/// a stateful one in `jacobians(in, state, out)` (a stop on an angle that counts turns).
template <class E>
concept HasStatelessForceJacobians =
    requires(const E& e, const InputOf<E>& in, ForceBlocksOf<E>& out) { e.jacobians(in, out); };
template <class E>
concept HasStatefulForceJacobians =
    StatefulForce<E> && requires(const E& e, const InputOf<E>& in, const typename E::State& s,
                                 ForceBlocksOf<E>& out) { e.jacobians(in, s, out); };
template <class E>
concept HasForceJacobians = HasStatelessForceJacobians<E> || HasStatefulForceJacobians<E>;

/// The blocks of d(Phi_q^T lambda)/dq that an element's constraint forces add to the Newton
/// matrix (their "geometric stiffness"), body by body: block k is the derivative of body k's
/// share J_k^T lambda with respect to body k's own velocity coordinates. The couplings between
/// two bodies are left out, so the iteration matrix keeps the pattern of M.
template <class Space, int NB>
using GeometricStiffness = std::array<Eigen::Matrix<double, Space::nv, Space::nv>, NB>;

/// Optional: a constraint whose `add_geometric_stiffness(in, lambda, out)` adds, to each body's
/// block of `out`, the derivative of its share of Phi_q^T lambda. Without it, Newton's matrix
/// lacks that term, which slows the iteration where lambda is large against the bodies' mass
/// over the step squared (a long chain whipping round: 1/10 a step at 2048 links).
template <class E>
concept HasGeometricStiffness = Constraint<E> &&
    requires(const E& e, const InputOf<E>& in,
             const Eigen::Matrix<double, E::num_equations, 1>& lambda,
             GeometricStiffness<typename E::Space, E::num_bodies>& out) {
  e.add_geometric_stiffness(in, lambda, out);
};

/// Optional: a stateful element that limits the next step from its state (an angle that counts
/// whole turns from the last accepted one must turn by less than half a turn in a step). The
/// integrators take no longer step than the smallest limit; without it, there is none.
template <class E>
concept LimitsSteps =
    Stateful<E> && requires(const E& e, const InputOf<E>& in, const typename E::State& s) {
      { e.step_limit(in, s) } -> std::convertible_to<double>;
    };

/// Optional: an element that sits on a joint added to the model before it (joint friction).
/// Model::add finds the joint by `joint_name()` and calls `attach(joint, type, index)` with
/// it and its place in the model (its type's position in the model's list, its index there).
template <class E>
concept OnJoint = NamedElement<E> && requires(const E& e) {
  { e.joint_name() } -> std::convertible_to<std::string>;
  { e.joint_type() } -> std::convertible_to<std::size_t>;
  { e.joint_index() } -> std::convertible_to<std::size_t>;
};

/// Optional: a stateful force on a joint whose law reads the joint's reaction (friction from
/// the normal load). Its state's `reaction` is the joint's constraint force on its body b,
/// -Phi_q,b^T lambda, which the system refreshes from the multipliers before each evaluation.
template <class E>
concept ReadsJointReaction = StatefulForce<E> && OnJoint<E> && requires(typename E::State& s) {
  { s.reaction } -> std::convertible_to<typename E::Space::Velocity>;
};

/// Optional: a force element with a potential energy.
template <class E>
concept HasPotential = requires(const E& e, const InputOf<E>& in) {
  { e.potential_energy(in) } -> std::convertible_to<double>;
};

/// Optional: a stateful force element whose potential energy also reads its state (a spring
/// that counts turns, for instance).
template <class E>
concept HasStatefulPotential = StatefulForce<E> &&
    requires(const E& e, const InputOf<E>& in, const typename E::State& s) {
  { e.potential_energy(in, s) } -> std::convertible_to<double>;
};

/// Optional: an element that completes its own description from the bodies' initial frames
/// (for example a reference direction the user left out). Called once, when it is added.
template <class E>
concept BindsToInitialPose = requires(E& e, const InputOf<E>& in) {
  e.bind(in);
};

/// The discrete state of an element type, or an empty placeholder.
template <class E>
struct StateOfImpl {
  struct None {};
  using type = None;
};
template <Stateful E>
struct StateOfImpl<E> {
  using type = typename E::State;
};
template <class E>
using StateOf = typename StateOfImpl<E>::type;

/// Fills a force element's Newton blocks, with its state if its jacobians read one.
template <class E>
  requires HasForceJacobians<E>
void force_jacobians(const E& e, const InputOf<E>& in, const StateOf<E>& state,
                     ForceBlocksOf<E>& out) {
  if constexpr (HasStatefulForceJacobians<E>)
    e.jacobians(in, state, out);
  else
    e.jacobians(in, out);
}

/// A constraint's Phi, Jacobian blocks and Phi_t, with its state if it has one.
template <Constraint E>
void evaluate_constraint(const E& e, const InputOf<E>& in, const StateOf<E>& state,
                         BlocksOf<E>& out) {
  if constexpr (StatefulConstraint<E>)
    e.evaluate(in, state, out);
  else
    e.evaluate(in, out);
}

/// A constraint's acceleration right-hand side, with its state if it has one.
template <Constraint E>
Eigen::Matrix<double, E::num_equations, 1> constraint_gamma(const E& e, const InputOf<E>& in,
                                                            const StateOf<E>& state) {
  if constexpr (StatefulConstraint<E>)
    return e.gamma(in, state);
  else
    return e.gamma(in);
}

}  // namespace odyn
