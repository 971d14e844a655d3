#pragma once
// What every time integrator provides, so that one driver (odyn/dynamics.hpp) runs any of
// them, lands on output times and ends steps exactly on the switches of force laws.
//
// An integrator owns the committed state (time t_n and whatever history it keeps) and writes
// trial states into the workspace:
//   attempt(h)    tries a step of size h from the committed state; the workspace then holds the
//                 trial state at t_n + h with frames, blocks, v' and lambda up to date (or, if
//                 the integrator has refresh_blocks(), with blocks that call brings up to date).
//                 False if the step could not be computed (Newton failed, singular matrix, NaN).
//   error_norm()  the local error of the last attempt in units of the tolerance (accept <= 1).
//   accept()      commits the attempt and proposes the next step size from its error.
//   reject()      rolls back and proposes a shorter step; throws SolverError once it is hopeless.
//   commit()      commits the attempt without touching the step-size proposal (event location).
//   rollback()    puts the workspace back at the committed state.
//   restart()     forgets the history after a discontinuity of the forces.
//   fail()        rolls back and throws the SolverError that explains the last failed attempt.
// Fixed-step integrators (`adaptive()` false) are driven by attempt/commit alone; adaptive ones
// may also interpolate within a step (dense output), so that output times do not cut steps.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>

namespace odyn {

/// The smallest rtol a run with error control uses (100 machine epsilons, SciPy's floor): a
/// smaller one only buys more steps whose rounding errors outgrow what they gain.
inline constexpr double rtol_floor = 100.0 * std::numeric_limits<double>::epsilon();

/// The rounding floor of a Newton iteration near a singular configuration (see
/// GeneralizedAlphaMethod::rounding_floor, BdfMethod::rounding_floor) is measured by a solve
/// with a right-hand side of rounding-sized entries; this sign for entry i, a fixed scramble
/// (Knuth's multiplicative hash), gives that right-hand side a part along every direction.
inline double rounding_probe_sign(Eigen::Index i) {
  return ((static_cast<unsigned>(i) * 2654435761u) & 0x10000u) != 0 ? 1.0 : -1.0;
}

/// Newton corrections up to this multiple of the measured rounding floor count as noise: a
/// rounding error of eps |q| in every entry of Phi is a typical one, not the largest.
inline constexpr double rounding_floor_factor = 10.0;

/// Counters every integrator keeps; reported by the analyses and the benchmarks.
struct IntegratorStatistics {
  long steps = 0;                 // accepted steps
  long rejected_steps = 0;        // attempts thrown away (error too large or Newton failed)
  long newton_iterations = 0;     // linear solves of a Newton iteration (or of a projection)
  long jacobian_evaluations = 0;  // iteration matrices assembled
  long factorizations = 0;        // of the iteration matrix or the mass-constraint matrix
  long residual_evaluations = 0;  // evaluations of Phi, Phi_q and Q together
  long restarts = 0;              // after discontinuities and at the start
  long events = 0;                // located switches of force laws
  /// Steps whose Newton iteration ended at the rounding floor of a nearly singular constraint
  /// Jacobian (a singular configuration: see GeneralizedAlphaMethod::rounding_floor), or, for
  /// bdf, whose error test allowed for that noise; for dopri5 and dop853, steps whose stages
  /// were projected onto the constraints there (ExplicitRungeKutta::project_stage); for adams,
  /// steps whose positions (and velocities) were projected to rounding there
  /// (Adams::project_to_rounding).
  long singular_steps = 0;
  /// Largest local error estimate of an accepted step, in units of the tolerance (rtol, atol);
  /// a fixed-step run reports it too, against the tolerances it was given.
  double max_error_estimate = 0.0;
};

/// Step-size control shared by the integrators that have it.
struct StepControl {
  double rtol = 1e-6;        // relative tolerance of the local error per component of (q, v)
  double atol = 1e-6;        // absolute tolerance, in the units of each component
  double first_step = 1e-4;  // s; the controller adapts from there
  double max_step = std::numeric_limits<double>::infinity();  // s
  double min_step = 1e-14;  // s; below this a step is hopeless and the run stops
};

/// The weighted root-mean-square norm of a local error estimate:
/// sqrt(mean((e_i / (atol + rtol max(|a_i|, |b_i|)))^2)), the norm of DASSL and of Hairer's codes.
inline double weighted_rms_norm(const Eigen::Ref<const Eigen::VectorXd>& error,
                                const Eigen::Ref<const Eigen::VectorXd>& a,
                                const Eigen::Ref<const Eigen::VectorXd>& b, double rtol,
                                double atol) {
  if (error.size() == 0) return 0.0;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < error.size(); ++i) {
    const double scaled = error[i] / (atol + rtol * std::max(std::abs(a[i]), std::abs(b[i])));
    sum += scaled * scaled;
  }
  return std::sqrt(sum / static_cast<double>(error.size()));
}

/// The step-size factor of an elementary controller for a method whose local error is of order
/// `order + 1` in h: safety * error^(-1/(order + 1)), kept within [min_factor, max_factor].
inline double step_factor(double error, int order, double min_factor = 0.2, double max_factor = 5.0,
                          double safety = 0.9) {
  if (!std::isfinite(error)) return min_factor;
  if (error <= 0.0) return max_factor;
  return std::clamp(safety * std::pow(error, -1.0 / (order + 1)), min_factor, max_factor);
}

/// A time integrator as the dynamics driver uses it (see the top of this file).
template <class I>
concept StepIntegrator = requires(I& i, const I& ci, double h) {
  { i.attempt(h) } -> std::same_as<bool>;
  i.commit();
  i.rollback();
  i.restart();
  i.fail();
  i.count_event();
  { ci.adaptive() } -> std::convertible_to<bool>;
  { ci.time() } -> std::convertible_to<double>;
  { ci.statistics() } -> std::convertible_to<IntegratorStatistics>;
};

/// An integrator whose failed fixed step is a Newton iteration that did not converge: the
/// committed state is sound and a shorter step may pass (see advance_to). An explicit method's
/// failure follows an instability that has already spoiled the state, so it stops instead.
template <class I>
concept RetriesShorterSteps = StepIntegrator<I> && I::retries_shorter_steps;

/// An integrator with error control.
template <class I>
concept AdaptiveIntegrator = StepIntegrator<I> && requires(I& i, const I& ci) {
  { ci.error_norm() } -> std::convertible_to<double>;
  { ci.proposed_step() } -> std::convertible_to<double>;
  i.accept();
  i.reject();
};

/// An adaptive integrator with dense output: interpolate(t) puts the state at a time t within
/// the last attempted step into the workspace (consistent, with v' and lambda), and
/// restore_trial() puts the attempt's end state back. Output times then need not cut the steps.
/// interpolate_frames(t) is the cheap version for event location: positions and velocities
/// as interpolated, and the frames from them (no projection, no v').
template <class I>
concept DenseOutputIntegrator = AdaptiveIntegrator<I> && requires(I& i, double t) {
  { i.interpolate(t) } -> std::same_as<bool>;
  i.restore_trial();
  i.interpolate_frames(t);
};

}  // namespace odyn
