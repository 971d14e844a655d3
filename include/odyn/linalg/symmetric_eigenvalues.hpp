#pragma once
// Eigenvalues of a symmetric 3 x 3 matrix (an inertia tensor's principal moments) by cyclic
// Jacobi rotations: accurate to rounding relative to the matrix's norm even for repeated or
// nearly repeated eigenvalues (a disc's two equal moments), where the closed-form solution of
// the characteristic cubic loses half the digits. Written as plain loops: compiled in every
// translation unit, it costs a fraction of Eigen's general eigensolver.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace odyn {

/// The eigenvalues of the symmetric matrix `matrix`, in ascending order.
inline Eigen::Vector3d symmetric_eigenvalues(const Eigen::Matrix3d& matrix) {
  Eigen::Matrix3d a = matrix;
  constexpr int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int sweep = 0; sweep < 30; ++sweep) {
    const double off = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
    const double diagonal = a(0, 0) * a(0, 0) + a(1, 1) * a(1, 1) + a(2, 2) * a(2, 2);
    if (!(off > 1e-36 * diagonal)) break;  // off-diagonal below rounding (or not finite)
    for (const auto& [p, q] : pairs) {
      if (a(p, q) == 0.0) continue;
      // The rotation in the (p, q) plane that zeroes a(p, q) (Golub & Van Loan, Alg. 8.5.1).
      const double tau = (a(q, q) - a(p, p)) / (2.0 * a(p, q));
      const double t = std::abs(tau) > 1e150
                           ? 0.5 / tau
                           : std::copysign(1.0, tau) / (std::abs(tau) + std::sqrt(1.0 + tau * tau));
      const double c = 1.0 / std::sqrt(1.0 + t * t), s = t * c;
      for (int k = 0; k < 3; ++k) {  // columns: a J
        const double kp = a(k, p), kq = a(k, q);
        a(k, p) = c * kp - s * kq;
        a(k, q) = s * kp + c * kq;
      }
      for (int k = 0; k < 3; ++k) {  // rows: J^T (a J)
        const double pk = a(p, k), qk = a(q, k);
        a(p, k) = c * pk - s * qk;
        a(q, k) = s * pk + c * qk;
      }
    }
  }
  Eigen::Vector3d eigenvalues = a.diagonal();
  std::sort(eigenvalues.data(), eigenvalues.data() + 3);
  return eigenvalues;
}

}  // namespace odyn
