#pragma once
// The law of a bushing, shared by the spatial and the planar one: a spring-damper in every
// direction of a joint frame. In the displacement coordinates x of frame b relative to frame a
// (N = 6 in space: the translation, then the rotation vector, both in a's axes; N = 3 in the
// plane: the translation and the angle) and their rates x', the generalized force is
//     g = -K x - C x' + preload + law(t, x, x').
// K and C are symmetric and positive semidefinite: the spring then stores
// 1/2 x^T K x - preload . x, and the damper dissipates x'^T C x' (ADAMS's BUSHING is the
// diagonal K and C, its FIELD the full matrices).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <string>

#include "odyn/core/description.hpp"
#include "odyn/core/errors.hpp"

namespace odyn {

namespace parameters {
/// A bushing's bodies and frames: unlike a joint's, a frame's axes left out are its body's.
inline constexpr std::array<Parameter, 5> bushing_frames{{
    {"name", "name", nullptr, "", "the element's name"},
    {"body_a", "body", nullptr, "", "the first body"},
    {"on_a", "frame", "null", "m",
     "the bushing's frame on body a (axes left out: the body's; a reference left out: its x "
     "axis, or y)"},
    {"body_b", "body", nullptr, "", "the second body"},
    {"on_b", "frame", "null", "m", "the bushing's frame on body b (the same defaults)"},
}};

/// A bushing's law (after its two bodies and frames).
inline constexpr std::array<Parameter, 4> bushing_law{{
    {"stiffness", "component_matrix", "0", "N/m, N m/rad",
     "K: one number per component (a diagonal) or the full symmetric matrix"},
    {"damping", "component_matrix", "0", "N s/m, N m s/rad",
     "C: one number per component (a diagonal) or the full symmetric matrix"},
    {"preload", "wrench", "0", "N, N m", "the force and torque on b at zero displacement"},
    {"law", "wrench_law", "null", "N, N m",
     "law(t, x, x') -> an extra generalized force (a nonlinear bushing)"},
}};
}  // namespace parameters

template <int N>
struct BushingLaw {
  using Vector = Eigen::Matrix<double, N, 1>;
  using Matrix = Eigen::Matrix<double, N, N>;
  using Function = std::function<Vector(double t, const Vector& x, const Vector& rate)>;

  /// A displacement x and its rate x', the law's arguments.
  struct Displacement {
    Vector x;
    Vector rate;
  };

  Matrix stiffness = Matrix::Zero();  // K
  Matrix damping = Matrix::Zero();    // C
  Vector preload = Vector::Zero();
  Function law = {};  // optional

  template <class Reader>
  static BushingLaw from_parameters(Reader& r) {
    return {parameter<Matrix>(r, "stiffness"), parameter<Matrix>(r, "damping"),
            parameter<Vector>(r, "preload"), parameter<Function>(r, "law")};
  }

  /// Refuses non-finite values and a K or C that is not symmetric positive semidefinite.
  void check(const std::string& element) const {
    if (!preload.allFinite()) throw ModelError(element, "preload must be finite");
    check_matrix(stiffness, "stiffness", element);
    check_matrix(damping, "damping", element);
  }

  /// g at displacement x and rate x'.
  Vector force(double t, const Vector& x, const Vector& rate) const {
    Vector g = preload - stiffness * x - damping * rate;
    if (law) g += law(t, x, rate);
    return g;
  }

  /// The spring's and the preload's energy (the law's, if any, is not counted).
  double potential_energy(const Vector& x) const {
    return 0.5 * x.dot(stiffness * x) - preload.dot(x);
  }

 private:
  static std::string consequence(const char* what) {
    return std::string(what) == "stiffness" ? "the spring would push away from rest"
                                            : "the damper would feed energy in";
  }
  static void check_matrix(const Matrix& m, const char* what, const std::string& element) {
    if (!m.allFinite()) throw ModelError(element, std::string(what) + " must be finite");
    const double scale = m.cwiseAbs().maxCoeff();
    if (scale == 0.0) return;
    Eigen::Index row = 0, col = 0;
    if ((m - m.transpose()).cwiseAbs().maxCoeff(&row, &col) > 1e-12 * scale)
      throw ModelError(element, std::string(what) + " matrix is not symmetric: (" +
                                    std::to_string(row) + ", " + std::to_string(col) + ") is " +
                                    to_text(m(row, col)) + " but (" + std::to_string(col) + ", " +
                                    std::to_string(row) + ") is " + to_text(m(col, row)));
    const Matrix symmetric = 0.5 * (m + m.transpose());
    const double lowest = Eigen::SelfAdjointEigenSolver<Matrix>(symmetric).eigenvalues()[0];
    if (lowest < -1e-12 * scale)
      throw ModelError(element, std::string(what) +
                                    " matrix is not positive semidefinite (its lowest "
                                    "eigenvalue is " +
                                    to_text(lowest) + "): " + consequence(what));
  }
};

}  // namespace odyn
