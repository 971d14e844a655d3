#pragma once
// Static equilibrium: the configuration q where the applied forces balance the constraint
// forces, at rest,
//     Q(q) - Phi_q^T lambda = 0,   Phi(q) = 0.
// Newton's method iterates on the constraint manifold: each step solves with the exact tangent
// [K Phi_q^T; Phi_q 0] (analysis/tangent.hpp: the forces' stiffness and the constraints'
// geometric stiffness whole), then brings the positions back onto Phi = 0 and takes the
// multipliers that balance the forces best there, so that a large turn in absolute coordinates
// keeps its joints closed; a line search on the imbalance left keeps each step. When that fails
// from the start pose, two more attempts follow:
//  1. load steps, as Chrono's and ADAMS's statics take them: the start's unbalanced load r0 is
//     first held off and then let go, Q(q) - Phi_q^T lambda = (1 - s) (-r0) with s from 0 (the
//     start pose balances) to 1, each step's equilibrium the next one's start, a step that
//     fails halved;
//  2. relaxation (pseudo-transient continuation): steps with K + mu M, mu falling as the
//     imbalance does, which follow a heavily damped motion to a stable equilibrium.
// The equilibrium found is then judged by the stiffness along the motions the joints allow:
// the eigenvalues of K against M there (squared frequencies) name an unstable equilibrium (a
// negative one) and its direction. The linear algebra is dense (DenseStaticAlgebra, O(n^3)), or
// sparse for large models in absolute coordinates (SparseStaticAlgebra, about O(n)).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "odyn/analysis/absolute_coordinates.hpp"
#include "odyn/analysis/assembly.hpp"
#include "odyn/analysis/joint_coordinates.hpp"
#include "odyn/analysis/sparse_linearization.hpp"
#include "odyn/analysis/tangent.hpp"
#include "odyn/core/errors.hpp"

namespace odyn {

struct StaticSettings {
  /// Converged when max |Phi| <= tolerance (times the model's size if over 1 m) and the largest
  /// force imbalance <= tolerance times the force scale (the largest load, or the stiffness times
  /// the model's size where that is larger).
  double tolerance = 1e-12;
  int max_iterations = 60;    // iterations of each attempt and load step (relaxation: 4 times)
  bool load_stepping = true;  // when Newton fails from the start pose, apply the load in steps
  int max_load_steps = 64;
  /// When load steps fail too, relax: iterate as a heavily damped motion would settle.
  bool relaxation = true;
  std::string coordinates = "absolute";  // or "joint" (see analysis/joint_coordinates.hpp)
  /// "dense": tangents and solves as dense matrices, O(n^3); "sparse": in absolute coordinates,
  /// about linear in the model's size (analysis/sparse_linearization.hpp), the stability judged
  /// from the lowest few squared frequencies; "automatic": sparse in absolute coordinates above
  /// `sparse_above` velocity coordinates, else dense.
  std::string method = "automatic";
  static constexpr int sparse_above = 600;
};

/// How stiff an equilibrium is along the motions its joints allow.
struct Stability {
  bool stable = true;    // no direction of negative stiffness
  bool neutral = false;  // a direction with no stiffness at all (a free wheel, say)
  /// The eigenvalues of the reduced stiffness against the reduced mass, ascending, 1/s^2: the
  /// squared natural frequencies, negative along an unstable direction.
  std::vector<double> squared_frequencies;
  /// The coordinates that move most along the least stiff direction ("arm.angle").
  std::vector<std::string> least_stiff;
};

struct StaticSummary {
  std::string method;                // "newton", "load steps" or "relaxation": what converged
  int iterations = 0;                // iterations, over every attempt and load step
  int load_steps = 0;                // load steps tried
  double constraint_residual = 0.0;  // max |Phi| at the equilibrium
  double force_residual = 0.0;       // max force imbalance / force_scale
  double force_scale = 0.0;          // N (N m): see StaticSettings::tolerance
  double length_scale = 0.0;         // m: the model's size, for Phi and the difference steps
  Stability stability;
};

namespace detail {

/// The model's size: the largest distance of a body's centre from the centres' mean (the
/// global origin counted in), 1 if every centre is at the origin.
template <class Model>
double model_size(const Model& model, const Workspace<Model>& ws) {
  using Vector = typename Model::Space::Vector;
  Vector mean = Vector::Zero();
  for (int b = 1; b <= model.num_bodies(); ++b) mean += ws.frames[b].position;
  mean /= static_cast<double>(model.num_bodies() + 1);
  double size = mean.norm();
  for (int b = 1; b <= model.num_bodies(); ++b)
    size = std::max(size, (ws.frames[b].position - mean).norm());
  return size > 0.0 ? size : 1.0;
}

/// An orthonormal basis of the null space of `jacobian` (n x (n - rank)): the motions the
/// constraints allow.
inline Eigen::MatrixXd null_space(const Eigen::MatrixXd& jacobian, Eigen::Index n) {
  if (jacobian.rows() == 0) return Eigen::MatrixXd::Identity(n, n);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeFullV);
  const Eigen::VectorXd& sigma = svd.singularValues();
  const double largest = sigma.size() > 0 ? sigma[0] : 0.0;
  Eigen::Index rank = 0;
  while (rank < sigma.size() && sigma[rank] > 1e-10 * largest) ++rank;
  return svd.matrixV().rightCols(n - rank);
}

/// The coordinates with the largest share of a motion, turns and travels compared through the
/// model's size.
inline std::vector<std::string> leading_coordinates(const Eigen::VectorXd& motion,
                                                    const std::vector<VelocityCoordinate>& names,
                                                    double length) {
  Eigen::VectorXd share(motion.size());
  for (Eigen::Index j = 0; j < motion.size(); ++j)
    share[j] = std::abs(motion[j]) / (names[static_cast<std::size_t>(j)].angular ? 1.0 : length);
  const double largest = share.size() > 0 ? share.maxCoeff() : 0.0;
  std::vector<std::string> out;
  for (Eigen::Index j = 0; j < share.size(); ++j)
    if (largest > 0.0 && share[j] >= 0.5 * largest)
      out.push_back(names[static_cast<std::size_t>(j)].text());
  return out;
}

inline std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

/// The squared frequencies of K against M along the motions the jacobian allows, ascending,
/// with their directions in the velocity coordinates (columns).
struct ReducedSpectrum {
  Eigen::VectorXd values;
  Eigen::MatrixXd directions;
  double largest = 0.0;  // the largest |value|, or an estimate where only the lowest are known
};
inline ReducedSpectrum reduced_spectrum(const Tangent& t) {
  const Eigen::MatrixXd basis = null_space(t.jacobian, t.stiffness.cols());
  ReducedSpectrum out;
  if (basis.cols() == 0) return out;
  const Eigen::MatrixXd stiffness =
      basis.transpose() * (0.5 * (t.stiffness + t.stiffness.transpose())) * basis;
  const Eigen::MatrixXd mass = basis.transpose() * (0.5 * (t.mass + t.mass.transpose())) * basis;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(stiffness, mass);
  if (solver.info() != Eigen::Success) {
    // The mass is not positive definite along some motion: the stiffness alone.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> plain(stiffness);
    out.values = plain.eigenvalues();
    out.directions = basis * plain.eigenvectors();
  } else {
    out.values = solver.eigenvalues();
    out.directions = basis * solver.eigenvectors();
  }
  out.largest = out.values.cwiseAbs().maxCoeff();
  return out;
}

/// Statics' linear algebra with dense matrices (see the file's comment).
struct DenseStaticAlgebra {
  using TangentType = Tangent;
  template <class Coordinates>
  Tangent tangent(Coordinates& c, double length) {
    return odyn::tangent(c, length, {.mass = true, .damping = false});
  }
  static double largest(const Eigen::MatrixXd& matrix) {
    return matrix.size() > 0 ? matrix.cwiseAbs().maxCoeff() : 0.0;
  }
  /// The least change of the positions (velocity coordinates) that removes Phi to first order,
  /// constraints evaluated.
  template <class Coordinates>
  Eigen::VectorXd correction(Coordinates& c) {
    const Eigen::MatrixXd jacobian = constraint_jacobian(c);
    return jacobian.completeOrthogonalDecomposition().solve(-c.constraint_values());
  }
  /// The multipliers that best balance `residual` (evaluated with none), least squares.
  template <class Coordinates>
  void balance(Coordinates& c, const Eigen::VectorXd& residual) {
    const Eigen::MatrixXd jacobian = constraint_jacobian(c);
    c.multipliers() = jacobian.transpose().completeOrthogonalDecomposition().solve(-residual);
  }
  /// The Newton step for rhs with [K + mu M, Phi_q^T; Phi_q, 0]; false if the matrix is
  /// singular and cannot balance rhs.
  bool step(const Tangent& t, double mu, const Eigen::VectorXd& rhs, Eigen::VectorXd& out) {
    const Eigen::Index n = t.stiffness.rows(), m = t.jacobian.rows();
    Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(n + m, n + m);
    matrix.topLeftCorner(n, n) = t.stiffness;
    if (mu != 0.0) matrix.topLeftCorner(n, n) += mu * t.mass;
    matrix.topRightCorner(n, m) = t.jacobian.transpose();
    matrix.bottomLeftCorner(m, n) = t.jacobian;
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> solver(matrix);
    out = solver.solve(rhs);
    return (matrix * out - rhs).norm() <= 1e-8 * rhs.norm();
  }
  ReducedSpectrum spectrum(const Tangent& t) { return reduced_spectrum(t); }
};

/// The same on sparse matrices for a large model in absolute coordinates: the constraint rows
/// kept are those that repeat no others at the start pose, the spectrum the lowest few.
template <class Model>
class SparseStaticAlgebra {
 public:
  using TangentType = SparseTangent;
  static constexpr int judged_modes = 6;  // the lowest squared frequencies found

  SparseStaticAlgebra(const Model& model, Workspace<Model>& ws) : model_(model), ws_(ws) {
    evaluate_constraints(model, ws);
    rows_ = kept_rows(model, ws);
  }
  template <class Coordinates>
  SparseTangent tangent(Coordinates& c, double length) {
    return sparse_tangent(c, model_, ws_, length, {.mass = true, .damping = false});
  }
  static double largest(const Eigen::SparseMatrix<double>& matrix) {
    double out = 0.0;
    for (Eigen::Index k = 0; k < matrix.nonZeros(); ++k)
      out = std::max(out, std::abs(matrix.valuePtr()[k]));
    return out;
  }
  template <class Coordinates>
  Eigen::VectorXd correction(Coordinates& c) {
    const Eigen::SparseMatrix<double> jacobian = kept_jacobian();
    const Eigen::Index n = jacobian.cols(), m = jacobian.rows();
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + m);
    for (std::size_t i = 0; i < rows_.size(); ++i)
      rhs[n + static_cast<Eigen::Index>(i)] = -c.constraint_values()[rows_[i]];
    SparseSaddleSolve solver;
    if (!solver.factorize(sparse_identity(n), jacobian)) return Eigen::VectorXd::Zero(n);
    solver.solve_in_place(rhs);
    return rhs.head(n);
  }
  template <class Coordinates>
  void balance(Coordinates& c, const Eigen::VectorXd& residual) {
    Eigen::VectorXd kept;
    c.multipliers().setZero();
    if (!least_squares_multipliers(kept_jacobian(), residual, kept)) return;
    for (std::size_t i = 0; i < rows_.size(); ++i)
      c.multipliers()[rows_[i]] = kept[static_cast<Eigen::Index>(i)];
  }
  bool step(const SparseTangent& t, double mu, const Eigen::VectorXd& rhs, Eigen::VectorXd& out) {
    const Eigen::Index n = t.stiffness.rows();
    const auto m = static_cast<Eigen::Index>(rows_.size());
    Eigen::VectorXd kept_rhs(n + m);
    kept_rhs.head(n) = rhs.head(n);
    for (Eigen::Index i = 0; i < m; ++i)
      kept_rhs[n + i] = rhs[n + rows_[static_cast<std::size_t>(i)]];
    SparseSaddleSolve solver;
    const bool regular =
        mu != 0.0 ? solver.factorize(t.stiffness + mu * t.mass, selected_rows(t.jacobian, rows_))
                  : solver.factorize(t.stiffness, selected_rows(t.jacobian, rows_));
    if (!regular) return false;
    solver.solve_in_place(kept_rhs);
    out = Eigen::VectorXd::Zero(rhs.size());
    out.head(n) = kept_rhs.head(n);
    for (Eigen::Index i = 0; i < m; ++i)
      out[n + rows_[static_cast<std::size_t>(i)]] = kept_rhs[n + i];
    return true;
  }
  ReducedSpectrum spectrum(const SparseTangent& t) {
    const LowestModes lowest =
        lowest_modes(t.stiffness, t.mass, selected_rows(t.jacobian, rows_), judged_modes);
    ReducedSpectrum out;
    out.values = lowest.values;
    out.directions = lowest.vectors;
    out.largest = std::max(lowest.values.size() > 0 ? lowest.values.cwiseAbs().maxCoeff() : 0.0,
                           lowest.largest_ratio);
    return out;
  }

 private:
  Eigen::SparseMatrix<double> kept_jacobian() const {
    return selected_rows(sparse_constraint_jacobian(model_, ws_), rows_);
  }
  const Model& model_;
  Workspace<Model>& ws_;
  std::vector<int> rows_;  // the constraint rows kept
};

/// Newton's method on the equilibrium, generic over the coordinates and the linear algebra
/// (see the file's comment).
template <class Coordinates, class Algebra = DenseStaticAlgebra>
class StaticSolver {
  using TangentType = typename Algebra::TangentType;

 public:
  StaticSolver(Coordinates& c, double t, double length, const StaticSettings& s,
               Algebra algebra = {})
      : algebra_(std::move(algebra)),
        c_(c),
        s_(s),
        t_(t),
        length_(length),
        n_(c.num_velocities()),
        m_(c.num_equations()),
        names_(c.velocity_coordinates()) {
    c_.velocities().setZero();
    c_.accelerations().setZero();
    c_.multipliers().setZero();
    start_q_ = c_.positions();
    start_load_.resize(n_);
    detail::residual_here(c_, start_load_);
    residual_.resize(n_);
  }

  StaticSummary solve() {
    StaticSummary out;
    out.length_scale = length_;
    out.method = "newton";
    if (!iterate(1.0, false, out.iterations)) {
      restore_start();
      out.method = "load steps";
      if (!s_.load_stepping || !step_load(out)) {
        restore_start();
        out.method = "relaxation";
        if (!s_.relaxation || !iterate(1.0, true, out.iterations))
          fail(out.iterations, std::string("by Newton's method") +
                                   (s_.load_stepping ? ", in load steps" : "") +
                                   (s_.relaxation ? " and by relaxation" : ""));
      }
    }
    finish(out);
    return out;
  }

 private:
  // The equilibrium's residual at load s: the force imbalance r - (1 - s) r0 and Phi.
  void evaluate(double s) {
    detail::residual_here(c_, residual_);
    residual_ -= (1.0 - s) * start_load_;
  }
  double force_scale(const TangentType& t) const {
    const double stiffness = Algebra::largest(t.stiffness);
    return std::max({start_load_.size() > 0 ? start_load_.cwiseAbs().maxCoeff() : 0.0,
                     stiffness * length_, std::numeric_limits<double>::min()});
  }
  double phi_tolerance() const { return s_.tolerance * std::max(1.0, length_); }
  bool converged(double force_scale) const {
    const double forces = n_ > 0 ? residual_.cwiseAbs().maxCoeff() : 0.0;
    const double phi = m_ > 0 ? c_.constraint_values().cwiseAbs().maxCoeff() : 0.0;
    return forces <= s_.tolerance * force_scale && phi <= phi_tolerance();
  }

  /// Brings the held positions onto Phi = 0 (least change, by Gauss-Newton with Phi_q's
  /// pseudo-inverse) and the multipliers to those that best balance the forces there (least
  /// squares), the force imbalance left evaluated at load s: Newton then iterates on the
  /// constraint manifold, where a large turn in absolute coordinates keeps its joints closed.
  /// False if the positions do not reach Phi = 0.
  bool settle(double s) {
    double phi = 0.0;
    for (int k = 0; m_ > 0; ++k) {
      c_.update_frames();
      c_.evaluate_constraints();
      const double previous = phi;
      phi = c_.constraint_values().cwiseAbs().maxCoeff();
      if (!std::isfinite(phi)) return false;
      // Done at a tenth of the tolerance, or where rounding stops the corrections.
      if (phi <= 0.1 * phi_tolerance() || (k > 2 && phi > 0.5 * previous) || k == 20) break;
      const Eigen::VectorXd correction = algebra_.correction(c_);
      const Eigen::VectorXd q = c_.positions();
      c_.integrate(q, correction, c_.positions());
    }
    if (phi > phi_tolerance()) return false;
    c_.multipliers().setZero();
    evaluate(s);
    if (m_ > 0) {
      algebra_.balance(c_, residual_);
      evaluate(s);
    }
    return true;
  }

  /// Newton's iteration at load s from the held positions (with a line search), or with
  /// `relax` the pseudo-transient one: each step solves with K + mu M, mu following the
  /// residual's fall (switched evolution relaxation), so that the iterate follows a heavily
  /// damped motion towards a stable equilibrium and turns into Newton near it. False (the
  /// state as it was) if it does not converge.
  bool iterate(double s, bool relax, int& iterations) {
    const Eigen::VectorXd first_q = c_.positions(), first_lambda = c_.multipliers();
    const auto give_up = [&] {
      last_q_ = c_.positions();
      c_.positions() = first_q;
      c_.multipliers() = first_lambda;
      return false;
    };
    if (!settle(s)) return give_up();
    const int budget = relax ? 4 * s_.max_iterations : s_.max_iterations;
    double mu = -1.0, last_norm = 0.0;  // relax: the mass added to K (1/s^2), set at the start
    for (int it = 0;; ++it) {
      const TangentType t = algebra_.tangent(c_, length_);
      const double scale = force_scale(t);
      evaluate(s);
      if (converged(scale)) return true;
      if (it == budget) return give_up();
      ++iterations;
      const double norm = residual_.norm();
      const double mass = n_ > 0 ? Algebra::largest(t.mass) : 1.0;
      // Stiffness over mass: the scale of the squared frequencies.
      const double mu_unit = (Algebra::largest(t.stiffness) + scale / length_) / mass;
      if (relax) {
        // Switched evolution relaxation: mu falls as the imbalance does, down to Newton's 0.
        mu = mu < 0.0 ? mu_unit : mu * norm / last_norm;
        if (mu < 1e-10 * mu_unit) mu = 0.0;
      }
      last_norm = norm;
      const Eigen::VectorXd q = c_.positions();
      Eigen::VectorXd rhs(n_ + m_);
      rhs << -residual_, -c_.constraint_values();
      bool stepped = false;
      for (int attempt = 0; attempt < 12 && !stepped; ++attempt) {
        Eigen::VectorXd step;
        // A singular tangent that cannot balance the residual gives no step.
        const bool consistent = algebra_.step(t, relax ? mu : 0.0, rhs, step);
        if (!relax) {
          for (double alpha = 1.0; consistent && alpha >= 1.0 / 64.0 && !stepped; alpha *= 0.5) {
            c_.integrate(q, alpha * step.head(n_), c_.positions());
            stepped =
                settle(s) && (residual_.norm() < (1.0 - 1e-4 * alpha) * norm || converged(scale));
          }
          if (!stepped) return give_up();
        } else {
          // Any step that keeps the residual within twice the last; else a shorter one.
          if (consistent) {
            c_.integrate(q, step.head(n_), c_.positions());
            stepped = settle(s) && residual_.norm() <= 2.0 * norm;
          }
          if (!stepped) mu = mu <= 0.0 ? mu_unit : 10.0 * mu;
        }
      }
      if (!stepped) return give_up();
    }
  }

  void restore_start() {
    c_.positions() = start_q_;
    c_.multipliers().setZero();
  }

  /// Applies the start's unbalanced load in steps (see the file's comment), each step's
  /// equilibrium by Newton; a step that fails is halved. False if the steps run out.
  bool step_load(StaticSummary& out) {
    double done = 0.0, step = 0.25;
    while (done < 1.0) {
      if (out.load_steps >= s_.max_load_steps) return false;
      const double next = std::min(1.0, done + step);
      ++out.load_steps;
      if (iterate(next, false, out.iterations)) {
        done = next;
        step *= 1.5;
      } else {
        step *= 0.5;
      }
    }
    return true;
  }

  void finish(StaticSummary& out) {
    const TangentType t = algebra_.tangent(c_, length_);
    evaluate(1.0);
    out.force_scale = force_scale(t);
    out.force_residual = n_ > 0 ? residual_.cwiseAbs().maxCoeff() / out.force_scale : 0.0;
    out.constraint_residual = m_ > 0 ? c_.constraint_values().cwiseAbs().maxCoeff() : 0.0;
    const ReducedSpectrum spectrum = algebra_.spectrum(t);
    Stability& stability = out.stability;
    stability.squared_frequencies.assign(spectrum.values.begin(), spectrum.values.end());
    if (spectrum.values.size() == 0) return;
    const double largest = spectrum.largest;
    // Below this, a squared frequency is the differences' rounding, not stiffness.
    const double noise = 1e-8 * std::max(largest, std::numeric_limits<double>::min());
    stability.stable = spectrum.values[0] >= -noise;
    stability.neutral = std::abs(spectrum.values[0]) < noise;
    stability.least_stiff = leading_coordinates(spectrum.directions.col(0), names_, length_);
  }

  /// A motion the loads drive that nothing stiffens at the held state: along a direction of
  /// the reduced stiffness (against the mass), moving the model by its own size calls up less
  /// than a millionth of the load along it. The coordinates it moves most; empty if none.
  std::vector<std::string> free_motion() {
    const TangentType t = algebra_.tangent(c_, length_);
    evaluate(1.0);
    const ReducedSpectrum spectrum = algebra_.spectrum(t);
    for (Eigen::Index k = 0; k < spectrum.values.size(); ++k) {
      const Eigen::VectorXd direction = spectrum.directions.col(k);
      double size = 0.0;  // the direction's largest travel, turns counted through the size
      for (Eigen::Index j = 0; j < n_; ++j)
        size = std::max(size, std::abs(direction[j]) *
                                  (names_[static_cast<std::size_t>(j)].angular ? length_ : 1.0));
      const double load = std::abs(direction.dot(residual_));
      if (size > 0.0 && std::abs(spectrum.values[k]) * length_ / size < 1e-6 * load)
        return leading_coordinates(direction, names_, length_);
    }
    return {};
  }

  /// Throws the reason no equilibrium was found: a free motion the loads drive, if the start
  /// pose and the last iterate both show one, or else the force imbalance left.
  [[noreturn]] void fail(int iterations, const std::string& how) {
    const Eigen::VectorXd reached = residual_;
    c_.positions() = last_q_.size() == start_q_.size() ? last_q_ : start_q_;
    const bool settled = settle(1.0);
    const std::vector<std::string> free_at_end =
        settled ? free_motion() : std::vector<std::string>{};
    restore_start();
    const std::vector<std::string> free_at_start = free_motion();
    if (!free_at_start.empty() && !free_at_end.empty())
      throw SolverError(t_, "no static equilibrium: the loads drive a free motion along " +
                                listed(free_at_start) +
                                ", which nothing stiffens; restrain it (a joint, a spring) or "
                                "run a dynamic analysis");
    Eigen::Index worst = 0;
    const double imbalance = reached.size() > 0 ? reached.cwiseAbs().maxCoeff(&worst) : 0.0;
    throw SolverError(t_, "no static equilibrium found " + how + " (" + std::to_string(iterations) +
                              " iterations); the largest force imbalance left, " +
                              to_text(imbalance) + ", is on " +
                              names_[static_cast<std::size_t>(worst)].text() +
                              ". Start from a pose nearer the equilibrium, or check that the "
                              "loads can be balanced");
  }

  Algebra algebra_;
  Coordinates& c_;
  const StaticSettings& s_;
  double t_;  // s: the time the drivers are held at
  double length_;
  Eigen::Index n_, m_;
  std::vector<VelocityCoordinate> names_;
  Eigen::VectorXd start_q_;     // the start pose's positions
  Eigen::VectorXd last_q_;      // the last iterate of the last attempt that failed
  Eigen::VectorXd start_load_;  // (n) r0: the residual at the start pose, lambda = 0
  Eigen::VectorXd residual_;    // (n) the force imbalance at the held state
};

/// Whether statics take the sparse path; refuses a method that does not apply.
template <class Model>
bool sparse_statics(const Model& model, const StaticSettings& s) {
  if (s.method != "automatic" && s.method != "dense" && s.method != "sparse")
    throw ModelError("static analysis",
                     "method '" + s.method + "' unknown; use 'automatic', 'dense' or 'sparse'");
  if (s.method == "sparse" && s.coordinates != "absolute")
    throw ModelError("static analysis",
                     "the sparse method runs in absolute coordinates; use coordinates "
                     "'absolute' or the dense method");
  return s.method == "sparse" || (s.method == "automatic" && s.coordinates == "absolute" &&
                                  model.num_velocities() > StaticSettings::sparse_above);
}

}  // namespace detail

/// Finds the static equilibrium near the workspace's pose at time ws.t (see the file's
/// comment) and leaves it in the workspace: q, v = v' = 0, and lambda, whose reactions
/// (odyn::reaction) hold the mechanism there and whose drivers' efforts hold their motions. The
/// summary judges its stability. Throws SolverError naming a free motion the loads drive, or
/// the force imbalance left, when no equilibrium is found.
template <class Model>
StaticSummary static_equilibrium(const Model& model, Workspace<Model>& ws,
                                 const StaticSettings& s = {}) {
  if (s.coordinates != "absolute" && s.coordinates != "joint")
    throw ModelError("static analysis",
                     "coordinates '" + s.coordinates + "' unknown; use 'absolute' or 'joint'");
  detail::sparse_statics(model, s);  // refuses a method that does not apply
  if (!(s.tolerance > 0.0) || !(s.max_iterations > 0) || !(s.max_load_steps > 0))
    throw ModelError("static analysis",
                     "tolerance, max_iterations and max_load_steps must be positive, got " +
                         to_text(s.tolerance) + ", " + std::to_string(s.max_iterations) + ", " +
                         std::to_string(s.max_load_steps));
  AssemblySettings start;
  start.tolerance = std::min(s.tolerance, 1e-10);
  assemble_positions(model, ws, start);
  ws.v.setZero();
  ws.vdot.setZero();
  update_frames(model, ws);
  initialize_states(model, ws);
  const double length = detail::model_size(model, ws);
  if (s.coordinates == "joint") {
    JointCoordinates<Model> c(model, ws);
    const StaticSummary out = detail::StaticSolver(c, ws.t, length, s).solve();
    c.update_frames();
    c.evaluate_constraints();
    c.evaluate_forces();
    c.complete_workspace();
    return out;
  }
  if (detail::sparse_statics(model, s)) {
    AbsoluteCoordinates<Model> c(model, ws, LinearSolver::automatic);
    const StaticSummary out =
        detail::StaticSolver(c, ws.t, length, s, detail::SparseStaticAlgebra<Model>(model, ws))
            .solve();
    Eigen::VectorXd residual(c.num_velocities());
    detail::residual_here(c, residual);  // the blocks and forces at the equilibrium
    return out;
  }
  AbsoluteCoordinates<Model> c(model, ws, LinearSolver::dense);
  const StaticSummary out = detail::StaticSolver(c, ws.t, length, s).solve();
  Eigen::VectorXd residual(c.num_velocities());
  detail::residual_here(c, residual);  // the blocks and forces at the equilibrium
  return out;
}

}  // namespace odyn
