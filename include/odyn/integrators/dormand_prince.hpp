#pragma once
// Explicit Dormand-Prince 5(4) ("dopri5") with step-size control, on the index-1 form of the
// equations of motion, projected onto the constraints after every step (see
// explicit_runge_kutta.hpp). Seven stages, the last at the new point (first same as last):
// six new saddle-point factorizations per step, and the projection starts from the seventh.
//
// Coefficients: J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta formulae",
// J. Comput. Appl. Math. 6 (1980); the continuous extension of order 4: L. F. Shampine,
// "Some practical Runge-Kutta formulas", Math. Comp. 46 (1986), as in Hairer, Norsett & Wanner,
// "Solving Ordinary Differential Equations I", Sect. II.6.

#include <array>

#include "odyn/analysis/joint_coordinates.hpp"
#include "odyn/integrators/explicit_runge_kutta.hpp"

namespace odyn {

struct DormandPrince5Tableau {
  static constexpr const char* name = "dopri5";
  static constexpr int order = 5;
  static constexpr int error_order = 4;
  static constexpr int stages = 7;
  static constexpr bool last_stage_is_new_point = true;
  static constexpr double min_step_factor = 0.2, max_step_factor = 5.0;
  static constexpr double stabilization_exponent = 0.04;  // as in Hairer's DOPRI5
  static constexpr double stiffness_bound = 3.25;         // as in DOPRI5
  static constexpr std::array<double, stages> c = {0.0,     1.0 / 5, 3.0 / 10, 4.0 / 5,
                                                   8.0 / 9, 1.0,     1.0};
  static constexpr std::array<std::array<double, stages>, stages> a = {{
      {},
      {1.0 / 5},
      {3.0 / 40, 9.0 / 40},
      {44.0 / 45, -56.0 / 15, 32.0 / 9},
      {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
      {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
      {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84},
  }};
  static constexpr std::array<double, stages> b = a[6];
  // Fifth-order weights minus fourth-order ones: the local error estimate.
  static constexpr std::array<double, stages> error_weights = {
      71.0 / 57600, 0.0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200, 22.0 / 525, -1.0 / 40};
  // Shampine's extension needs no extra stage; its one row weighs k_0..k_6 and f at the
  // projected end point (k_7), which stands in for the seventh stage.
  static constexpr int extra_stages = 0;
  static constexpr std::array<double, 0> extra_c = {};
  static constexpr std::array<std::array<double, stages + 1>, 0> extra_a = {};
  static constexpr int dense_rows = 1;
  static constexpr std::array<std::array<double, stages + 1>, dense_rows> dense = {{
      {-12715105075.0 / 11282082432.0, 0.0, 87487479700.0 / 32700410799.0,
       -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0, -1453857185.0 / 822651844.0,
       0.0, 69997945.0 / 29380423.0},
  }};
};

template <class Model, class Solver = BlockSchurSaddlePoint<Model>>
using DormandPrince =
    ExplicitRungeKutta<DormandPrince5Tableau, Model, AbsoluteCoordinates<Model, Solver>>;

/// The same method on joint coordinates (see analysis/joint_coordinates.hpp).
template <class Model>
using JointDormandPrince =
    ExplicitRungeKutta<DormandPrince5Tableau, Model, JointCoordinates<Model>>;

}  // namespace odyn
