#pragma once
// The names of the factorizations behind the analyses' linear solves (the `linear_solver`
// setting in C++, Python, scene files and the command line).

#include <string>

#include "odyn/core/errors.hpp"

namespace odyn {

/// Which factorization the saddle-point systems use.
///  - dense:   the dense Schur complement (envelope Cholesky) when A is block diagonal, else a
///             dense LU of the whole matrix; the dense assembly (rank-revealing QR);
///  - cholmod: the Schur complement, sparse, by CHOLMOD (A must be block diagonal);
///  - klu:     the whole matrix, sparse, by KLU;
///  - automatic ("auto"): dense for small models, cholmod for large ones whose A is block
///             diagonal, klu for large ones whose force elements couple bodies; the sparse
///             assembly for large models (see BlockSchurSaddlePoint::choose_path and
///             sparse_assembly in analysis/assembly.hpp for the sizes).
enum class LinearSolver { automatic, dense, cholmod, klu };

inline const char* linear_solver_name(LinearSolver solver) {
  switch (solver) {
    case LinearSolver::dense:
      return "dense";
    case LinearSolver::cholmod:
      return "cholmod";
    case LinearSolver::klu:
      return "klu";
    default:
      return "auto";
  }
}

/// The solver named "auto", "dense", "cholmod" or "klu"; ModelError for another name.
inline LinearSolver linear_solver_from_name(const std::string& name) {
  for (const LinearSolver solver :
       {LinearSolver::automatic, LinearSolver::dense, LinearSolver::cholmod, LinearSolver::klu})
    if (name == linear_solver_name(solver)) return solver;
  throw ModelError("linear_solver",
                   "unknown linear solver '" + name + "'; choose auto, dense, cholmod or klu");
}

}  // namespace odyn
