#pragma once
// Elements written in Python: forces (UserForceT) and constraint equations (UserConstraintT)
// whose functions are Python callables, with their Jacobians from the user or from differences.

#include <array>
#include <atomic>
#include <memory>
#include <string>

#include <odyn/core/difference_jacobians.hpp>
#include <odyn/odyn.hpp>
#include <odyn/python/callable.hpp>

namespace odyn::python {

namespace py = pybind11;

/// A force and torque on N bodies from a Python callable: function(t, body_0, ...,
/// body_{N-1}) -> per body the global force at its centre of mass, then the global torque
/// (spatial: 3 + 3 numbers; planar: 2 + 1). Implicit integrators get its stiffness and damping
/// from the user's `jacobians` function if there is one (checked once against differences, as
/// its conventions are easy to get wrong), else by central differences, or not at all.
template <class SpaceT, int N>
class UserForceT {
 public:
  using Space = SpaceT;
  static constexpr int num_bodies = N;
  static constexpr int width = Space::dim + Space::nw;  // numbers per body
  static constexpr int size = N * Space::nv;            // rows and columns of a block

  static constexpr std::array<Parameter, 5> parameter_list{{
      {"name", "name", nullptr, "", "the element's name"},
      {"bodies", "bodies", nullptr, "", "the one or two bodies it acts on"},
      {"function", "callable", nullptr, "N, N m",
       "function(t, body_0[, body_1]) -> per body the global force at the centre of mass, "
       "then the global torque"},
      {"jacobians", "optional_function", "null", "",
       "jacobians(t, body_0[, body_1]) -> (stiffness, damping): -dQ/dq and -dQ/dv over the "
       "bodies' velocity coordinates (6 per body in space: the centre globally, then a turn about "
       "the body's axes; Q's torque in body axes), each a square array or None; checked once "
       "against differences"},
      {"difference_jacobians", "flag", "true", "",
       "without jacobians, give implicit integrators the force's stiffness and damping by "
       "central differences (12 calls per body and Newton matrix); false: none"},
  }};
  static constexpr ElementDescription description{
      "user_force", "force",
      "A force written in Python on one or two bodies (the body views are refreshed before "
      "each call: copy them to keep them).",
      parameter_list};

  UserForceT(std::string name, const std::array<BodyId, N>& bodies,
             std::shared_ptr<Callable<Space>> function, bool difference_jacobians = true,
             std::shared_ptr<Callable<Space>> jacobians = nullptr)
      : name_(std::move(name)),
        bodies_(bodies),
        function_(std::move(function)),
        jacobians_(std::move(jacobians)),
        difference_jacobians_(difference_jacobians) {}

  const std::string& name() const { return name_; }
  const std::array<BodyId, N>& bodies() const { return bodies_; }

  void evaluate(const ElementInput<Space, N>& in, ForceBlocks<Space, N>& out) const {
    std::array<double, width * N> values;
    {
      py::gil_scoped_acquire gil;
      const py::object result = function_->call_with_frames(in.t, in.frames.data());
      read_numbers(result, values.data(), width * N, function_->what());
    }
    for (int k = 0; k < N; ++k) {
      const Eigen::Map<const typename Space::Vector> force(values.data() + width * k);
      const Eigen::Map<const typename Space::Angular> torque(values.data() + width * k +
                                                             Space::dim);
      out.force[k].template head<Space::dim>() = force;
      out.force[k].template tail<Space::nw>() = in.body(k).torque_to_body(torque);
    }
  }

  /// Stiffness and damping for implicit integrators' Newton matrices: the user's, by central
  /// differences of the Python function, or none (if the user turned them off).
  void jacobians(const ElementInput<Space, N>& in, ForceBlocks<Space, N>& out) const {
    if (jacobians_) {
      user_jacobians(in, out);
      if (!checked_->load()) {
        check_against_differences(in, out);
        checked_->store(true);  // only once they passed: a model refused stays refused
      }
    } else if (difference_jacobians_) {
      difference_jacobians(*this, in, out);
    } else {
      out.stiffness.setZero();
      out.damping.setZero();
    }
  }

 private:
  using Block = Eigen::Matrix<double, size, size, Eigen::RowMajor>;

  void user_jacobians(const ElementInput<Space, N>& in, ForceBlocks<Space, N>& out) const {
    py::gil_scoped_acquire gil;
    const py::object result = jacobians_->call_with_frames(in.t, in.frames.data());
    const std::string what = jacobians_->what();
    if (!py::isinstance<py::tuple>(result) && !py::isinstance<py::list>(result))
      throw py::type_error(what + ": jacobians must return (stiffness, damping), got " +
                           std::string(py::repr(result)));
    const py::sequence pair = result.cast<py::sequence>();
    if (pair.size() != 2)
      throw py::type_error(what + ": jacobians must return two blocks (stiffness, damping), got " +
                           std::to_string(pair.size()));
    const auto read = [&](py::handle value, const char* which, auto& to) {
      if (value.is_none()) {
        to.setZero();
        return;
      }
      Block block;
      read_numbers(value, block.data(), size * size,
                   what + " jacobians' " + which + " (" + std::to_string(size) + " x " +
                       std::to_string(size) + ")");
      to = block;
    };
    read(pair[0], "stiffness", out.stiffness);
    read(pair[1], "damping", out.damping);
  }

  /// Refuses user blocks that central differences contradict, naming the worst entry.
  void check_against_differences(const ElementInput<Space, N>& in,
                                 const ForceBlocks<Space, N>& given) const {
    ForceBlocks<Space, N> differences;
    difference_jacobians(*this, in, differences);
    const auto compare = [&](const auto& user, const auto& reference, const char* which) {
      const double scale = std::max(user.cwiseAbs().maxCoeff(), reference.cwiseAbs().maxCoeff());
      Eigen::Index row = 0, col = 0;
      const double worst = (user - reference).cwiseAbs().maxCoeff(&row, &col);
      if (worst > 1e-4 * scale + 1e-9)
        throw ModelError(name_, std::string("the ") + which + " block from jacobians() at (" +
                                    std::to_string(row) + ", " + std::to_string(col) + ") is " +
                                    to_text(user(row, col)) + " but central differences give " +
                                    to_text(reference(row, col)) + " at t = " + to_text(in.t) +
                                    "; see the jacobians parameter for the conventions");
    };
    compare(given.stiffness, differences.stiffness, "stiffness");
    compare(given.damping, differences.damping, "damping");
  }

  std::string name_;
  std::array<BodyId, N> bodies_;
  std::shared_ptr<Callable<Space>> function_;
  std::shared_ptr<Callable<Space>> jacobians_;  // null: none given
  bool difference_jacobians_ = true;
  // Whether the user's blocks were compared with differences (shared by the copies of a model).
  std::shared_ptr<std::atomic<bool>> checked_ = std::make_shared<std::atomic<bool>>(false);
};
static_assert(StatelessForce<UserForceT<Spatial, 1>> && StatelessForce<UserForceT<Spatial, 2>>);
static_assert(StatelessForce<UserForceT<Planar, 1>> && StatelessForce<UserForceT<Planar, 2>>);

/// One constraint equation written in Python on one or two bodies, phi(t, body_0[, body_1]) = 0,
/// as ADAMS's GCON. On one body it acts between the ground (side a) and that body (side b), so
/// that its reactions read as a joint's. Its gradient (with dphi/dt) and its gamma come from the
/// user's functions, compared once with differences of phi (their conventions are easy to get
/// wrong), or from those differences: 12 calls per body and 2 more for the gradient, 4 for gamma.
template <class SpaceT>
class UserConstraintT {
 public:
  using Space = SpaceT;
  using Input = ElementInput<Space, 2>;
  static constexpr int num_bodies = 2;
  static constexpr int num_equations = 1;

  static constexpr std::array<Parameter, 5> parameter_list{{
      {"name", "name", nullptr, "", "the element's name"},
      {"bodies", "bodies", nullptr, "", "the one or two bodies it constrains"},
      {"function", "callable", nullptr, "",
       "function(t, body_0[, body_1]) -> phi, one number, zero where the constraint holds"},
      {"jacobian", "optional_function", "null", "",
       "jacobian(t, body_0[, body_1]) -> the gradient of phi over the bodies' velocity "
       "coordinates (6 per body in space: the centre globally, then a turn about the body's "
       "axes; x, y, phi in the plane), then dphi/dt; checked once against differences (none: "
       "differences of phi)"},
      {"gamma", "optional_function", "null", "",
       "gamma(t, body_0[, body_1]) -> -(phi's second derivative along the motion at the bodies' "
       "present velocities, kept constant in body axes); checked once against differences "
       "(none: differences of phi)"},
  }};
  static constexpr ElementDescription description{
      "user_constraint", "joint",
      "One constraint equation written in Python on one or two bodies, phi(t, body_0[, "
      "body_1]) = 0 (ADAMS's GCON). 1 equation.",
      parameter_list};

  /// `bodies`: the bodies the functions are given, one or two; the functions are built for as
  /// many.
  UserConstraintT(std::string name, const std::vector<BodyId>& bodies,
                  std::shared_ptr<Callable<Space>> function,
                  std::shared_ptr<Callable<Space>> jacobian = nullptr,
                  std::shared_ptr<Callable<Space>> gamma = nullptr)
      : name_(std::move(name)),
        first_(bodies.size() == 1 ? 1 : 0),
        function_(std::move(function)),
        jacobian_(std::move(jacobian)),
        gamma_(std::move(gamma)) {
    if (bodies.size() != 1 && bodies.size() != 2)
      throw ModelError(name_, "a user constraint acts on one or two bodies");
    bodies_ = bodies.size() == 1 ? std::array<BodyId, 2>{ground, bodies[0]}
                                 : std::array<BodyId, 2>{bodies[0], bodies[1]};
  }

  const std::string& name() const { return name_; }
  const std::array<BodyId, 2>& bodies() const { return bodies_; }

  void evaluate(const Input& in, ConstraintBlocks<Space, 1, 2>& out) const {
    py::gil_scoped_acquire gil;
    out.phi[0] = value(in, in.t);
    const Row row = jacobian_ ? user_row(in) : difference_row(in);
    if (jacobian_ && !jacobian_checked_->load()) {
      compare(row.tail(given_length()), difference_row(in).tail(given_length()), "jacobian", in.t);
      jacobian_checked_->store(true);
    }
    for (int k = 0; k < 2; ++k) {
      if (bodies_[k].is_ground())
        out.jacobian[k].setZero();
      else
        out.jacobian[k] = row.template segment<Space::nv>(k * Space::nv).transpose();
    }
    out.phi_t[0] = row[2 * Space::nv];
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in) const {
    py::gil_scoped_acquire gil;
    if (!gamma_) return Eigen::Matrix<double, 1, 1>(difference_gamma(in));
    double given = 0.0;
    read_numbers(gamma_->call_with_frames(in.t, in.frames.data() + first_), &given, 1,
                 gamma_->what() + " gamma");
    // Compared once the bodies move: at rest both are often zero, which proves nothing.
    if (!gamma_checked_->load() && speed(in) > 0.0) {
      compare(Eigen::Matrix<double, 1, 1>(given), Eigen::Matrix<double, 1, 1>(difference_gamma(in)),
              "gamma", in.t);
      gamma_checked_->store(true);
    }
    return Eigen::Matrix<double, 1, 1>(given);
  }

 private:
  // The gradient over both bodies' velocity coordinates, then dphi/dt.
  using Row = Eigen::Matrix<double, 2 * Space::nv + 1, 1>;
  using Frames = std::array<typename Space::Frame, 2>;

  /// The numbers the user's jacobian gives: the gradient over the bodies it is given, and
  /// dphi/dt (the tail of a Row).
  int given_length() const { return (2 - first_) * Space::nv + 1; }

  double value(const Input& in, double t) const {
    double phi = 0.0;
    read_numbers(function_->call_with_frames(t, in.frames.data() + first_), &phi, 1,
                 function_->what());
    return phi;
  }
  /// phi with the bodies' frames replaced by `frames`.
  double value_at(const Input& in, const Frames& frames, double t) const {
    Input moved = in;
    for (int k = 0; k < 2; ++k) moved.frames[k] = &frames[k];
    return value(moved, t);
  }
  static typename Space::Velocity velocity_of(const typename Space::Frame& frame) {
    typename Space::Velocity v;
    v << frame.linear_velocity, frame.angular_velocity;
    return v;
  }
  static double speed(const Input& in) {
    return std::max(velocity_of(in.body(0)).norm(), velocity_of(in.body(1)).norm());
  }

  Row user_row(const Input& in) const {
    Row row = Row::Zero();
    read_numbers(jacobian_->call_with_frames(in.t, in.frames.data() + first_),
                 row.data() + first_ * Space::nv, given_length(),
                 jacobian_->what() + " jacobian (" + std::to_string(given_length()) + " numbers)");
    return row;
  }

  /// Central differences of phi along each velocity coordinate (the ground's stay zero) and in
  /// time.
  Row difference_row(const Input& in) const {
    Row row = Row::Zero();
    Frames frames{in.body(0), in.body(1)};
    for (int k = 0; k < 2; ++k) {
      if (bodies_[k].is_ground()) continue;
      const auto q = configuration_of<Space>(in.body(k));
      const auto v = velocity_of(in.body(k));
      const double h_position = 1e-6 * std::max(1.0, in.body(k).position.norm());
      for (int j = 0; j < Space::nv; ++j) {
        const double h = j >= Space::dim ? 1e-6 : h_position;
        std::array<double, 2> phi{};
        for (const int side : {0, 1}) {
          typename Space::Configuration moved;
          Space::integrate(q, (side == 0 ? h : -h) * Space::Velocity::Unit(j), moved);
          Space::make_frame(moved, v, frames[k]);
          phi[side] = value_at(in, frames, in.t);
        }
        row[k * Space::nv + j] = (phi[0] - phi[1]) / (2.0 * h);
      }
      frames[k] = in.body(k);
    }
    const double h_time = 1e-6 * std::max(1.0, std::abs(in.t));
    row[2 * Space::nv] = (value(in, in.t + h_time) - value(in, in.t - h_time)) / (2.0 * h_time);
    return row;
  }

  /// -phi'' along the motion with constant body velocities (as gamma is defined), by the
  /// five-point second difference; a step moves the fastest body by 1e-3 m or turns it by
  /// 1e-3 rad.
  double difference_gamma(const Input& in) const {
    const double h = 1e-3 / std::max(1.0, speed(in));
    const auto phi_after = [&](double dt) {
      Frames frames;
      for (int k = 0; k < 2; ++k) {
        const auto v = velocity_of(in.body(k));
        typename Space::Configuration moved;
        Space::integrate(configuration_of<Space>(in.body(k)), dt * v, moved);
        Space::make_frame(moved, v, frames[k]);
      }
      return value_at(in, frames, in.t + dt);
    };
    const double second = (-phi_after(2.0 * h) + 16.0 * phi_after(h) - 30.0 * phi_after(0.0) +
                           16.0 * phi_after(-h) - phi_after(-2.0 * h)) /
                          (12.0 * h * h);
    return -second;
  }

  /// Refuses a user's value that the differences contradict, naming the worst entry.
  template <class Given, class Reference>
  void compare(const Given& given, const Reference& reference, const char* which, double t) const {
    const double scale = std::max(given.cwiseAbs().maxCoeff(), reference.cwiseAbs().maxCoeff());
    Eigen::Index row = 0;
    const double worst = (given - reference).cwiseAbs().maxCoeff(&row);
    if (worst > 1e-5 * scale + 1e-7)
      throw ModelError(name_, std::string("the ") + which + "() value " +
                                  (given.size() > 1 ? "[" + std::to_string(row) + "] " : "") +
                                  "is " + to_text(given[row]) + " but differences of phi give " +
                                  to_text(reference[row]) + " at t = " + to_text(t) + "; see the " +
                                  which + " parameter for the conventions");
  }

  std::string name_;
  std::array<BodyId, 2> bodies_{};
  int first_ = 0;  // the first frame the functions see: 1 when given one body
  std::shared_ptr<Callable<Space>> function_;
  std::shared_ptr<Callable<Space>> jacobian_;  // null: differences
  std::shared_ptr<Callable<Space>> gamma_;     // null: differences
  // Whether the user's functions were compared with differences (shared by a model's copies).
  std::shared_ptr<std::atomic<bool>> jacobian_checked_ = std::make_shared<std::atomic<bool>>(false);
  std::shared_ptr<std::atomic<bool>> gamma_checked_ = std::make_shared<std::atomic<bool>>(false);
};
static_assert(StatelessConstraint<UserConstraintT<Spatial>> &&
              StatelessConstraint<UserConstraintT<Planar>>);

}  // namespace odyn::python
