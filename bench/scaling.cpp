// Scaling report: setup time and time per step against the model's size, on the large models
// mechanical engineers build (chains, ropes with springs, trees, ladders of closed loops), with
// generalized-alpha at h = 1e-3 and the default settings (linear_solver auto). Writes one CSV
// row per case and size and prints a table; bench/plot_scaling.py fits the growth exponents
// and draws the log-log figure (scripts/scaling.sh runs both, and the peers' script).
//
//   scaling [--out FILE.csv] [--min-n N] [--max-n N] [--case NAME]... [--quick]
//
// Cases (N bodies):
//   spherical-chain          N links of 1 m, 1 kg, ball joints, horizontal and at rest at the
//                            start: the rope;
//   spherical-chain-moving   the same with a velocity given on every link (0.1 m/s across):
//                            the assembly keeps what the joints allow;
//   spherical-chain-springs  the same with a spring-damper between the centres of neighbours
//                            (the Newton matrix couples the bodies: KLU on the whole matrix);
//   revolute-chain           hinges about y instead of balls;
//   binary-tree              a ball-jointed binary tree of links, breadth first;
//   four-bar-ladder          a column of four-bar loops (a bar hung on two ball-jointed
//                            links per cell), N / 3 closed loops;
//   four-bar-ladder-hinged   the loops on parallel hinges instead, in the plane of gravity:
//                            3 redundant equations per loop (N in all).
// The same models in joint coordinates (analysis/joint_coordinates.hpp), named with "-joint":
// spherical-chain-joint, revolute-chain-joint, binary-tree-joint and four-bar-ladder-joint (to
// N = 256: its N / 3 loops make each evaluation O(N^2)). There step_s is one forward-dynamics
// evaluation, what each stage of dopri5 or dop853 costs (the frames down the tree, the
// closures, the articulated-body factorization and solve), and setup_s the assembly plus the
// tree's construction. spherical-chain-joint-alpha and spherical-chain-moving-joint-alpha step
// the two chains with generalized-alpha in joint coordinates (step_s a step, as above).
// planar-revolute-chain and planar-revolute-chain-joint: revolute-chain as a planar model (the
// same motion, in the x-z plane), in absolute and joint coordinates.
// setup_s: assembly (positions, the given velocities, accelerations) plus the integrator's
// analysis, wall time. step_s: the median over 5 blocks of steps of the wall time per step
// (per h of simulated time where a step that failed to converge was cut, as in simulate()).
// peak_rss_mb: the process's peak resident memory once the case has run (sizes ascend, so it
// is the largest model's so far).

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

namespace {

namespace sp = odyn::spatial;
using Eigen::Vector3d;
using Model = sp::Model<sp::Spherical, sp::Revolute, sp::Gravity, sp::Tsda>;
using Clock = std::chrono::steady_clock;
constexpr double step = 1e-3;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

/// A link of 1 m and 1 kg along x with its centre at `centre`; if `moving`, given a velocity
/// of 0.1 m/s across the chain (every component given; the assembly keeps what the joints
/// allow), else at rest.
sp::Body link(int index, const Vector3d& centre, bool moving = false) {
  sp::Body body{.name = "link" + std::to_string(index),
                .mass = 1.0,
                .inertia = sp::Body::principal(5e-5, 1.0 / 12.0, 1.0 / 12.0),
                .position = centre};
  if (moving) {
    body.linear_velocity = {0.0, 0.1, 0.0};
    body.velocity_given = std::array<bool, 6>{true, true, true, true, true, true};
  }
  return body;
}

enum class Joint { ball, hinge };

void add_joint(Model& model, Joint joint, const std::string& name, odyn::BodyId a,
               const Vector3d& on_a, odyn::BodyId b, const Vector3d& on_b) {
  if (joint == Joint::ball)
    model.add(sp::Spherical(name, a, on_a, b, on_b));
  else
    model.add(sp::Revolute(name, a, sp::JointFrame{on_a, Vector3d::UnitY()}, b,
                           sp::JointFrame{on_b, Vector3d::UnitY()}));
}

Model chain(int n, Joint joint, bool springs, bool moving = false) {
  Model model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < n; ++i) {
    const odyn::BodyId body = model.add_body(link(i, {0.5 + i, 0.0, 0.0}, moving));
    const Vector3d on_previous = previous.is_ground() ? Vector3d::Zero() : Vector3d(0.5, 0, 0);
    add_joint(model, joint, "joint" + std::to_string(i), previous, on_previous, body,
              {-0.5, 0.0, 0.0});
    if (springs && !previous.is_ground())
      model.add(sp::Tsda("spring" + std::to_string(i), previous, Vector3d::Zero(), body,
                         Vector3d::Zero(),
                         {.stiffness = 100.0, .damping = 1.0, .free_length = 1.0}));
    previous = body;
  }
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  return model;
}

/// Body k's children are 2k + 1 and 2k + 2 (from 0); each link hangs off its parent's far end,
/// the two children 0.3 m apart across it, all in the horizontal plane.
Model binary_tree(int n) {
  Model model;
  std::vector<odyn::BodyId> bodies;
  std::vector<Vector3d> far_end;
  for (int k = 0; k < n; ++k) {
    const int parent = (k - 1) / 2;
    const Vector3d start =
        k == 0 ? Vector3d(Vector3d::Zero())
               : Vector3d(far_end[parent] + Vector3d(0.0, k % 2 ? 0.15 : -0.15, 0.0));
    const odyn::BodyId body = model.add_body(link(k, start + Vector3d(0.5, 0.0, 0.0)));
    if (k == 0)
      model.add(sp::Spherical("joint0", odyn::ground, Vector3d::Zero(), body, {-0.5, 0.0, 0.0}));
    else
      model.add(sp::Spherical("joint" + std::to_string(k), bodies[parent],
                              {0.5, k % 2 ? 0.15 : -0.15, 0.0}, body, {-0.5, 0.0, 0.0}));
    bodies.push_back(body);
    far_end.push_back(start + Vector3d(1.0, 0.0, 0.0));
  }
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  return model;
}

/// Cells stacked along x: in each, a bar across y hangs on two links from the previous bar (or
/// the ground), on ball joints at all four corners: one closed loop a cell, without redundant
/// equations (four parallel hinges would repeat three equations a loop, and a planar hinge
/// four-bar in this pose is at a singular point). Each cell swings in and out of its plane and
/// its parts spin about their own axes. 3 bodies a cell.
/// With `hinged`, the loops lie in the x-y plane on hinges about z, under gravity along -y: a
/// parallelogram of four parallel hinges repeats 3 of its 20 equations, so the model is
/// over-constrained by N equations (the sparse Schur path pins them, see saddle_point.hpp).
Model four_bar_ladder(int n, bool hinged = false) {
  Model model;
  odyn::BodyId previous = odyn::ground;
  int index = 0;
  for (int cell = 0; 3 * cell + 3 <= std::max(n, 3); ++cell) {
    const double x0 = cell;  // the previous bar's line
    const odyn::BodyId left = model.add_body(link(index++, {x0 + 0.5, -0.5, 0.0}));
    const odyn::BodyId right = model.add_body(link(index++, {x0 + 0.5, 0.5, 0.0}));
    sp::Body bar = link(index++, {x0 + 1.0, 0.0, 0.0});
    bar.inertia = sp::Body::principal(1.0 / 12.0, 5e-3, 1.0 / 12.0);  // along y
    const odyn::BodyId across = model.add_body(bar);
    const std::string c = std::to_string(cell);
    // The previous bar's ends (or the ground's points) at y = -0.5 and 0.5.
    const auto joint = [&](const std::string& name, odyn::BodyId a, const Vector3d& on_a,
                           odyn::BodyId b, const Vector3d& on_b) {
      if (hinged)
        model.add(sp::Revolute(name, a, sp::JointFrame{on_a, Vector3d::UnitZ()}, b,
                               sp::JointFrame{on_b, Vector3d::UnitZ()}));
      else
        add_joint(model, Joint::ball, name, a, on_a, b, on_b);
    };
    joint("left-bottom" + c, previous, {0.0, -0.5, 0.0}, left, {-0.5, 0.0, 0.0});
    joint("left-top" + c, left, {0.5, 0.0, 0.0}, across, {0.0, -0.5, 0.0});
    joint("right-bottom" + c, previous, {0.0, 0.5, 0.0}, right, {-0.5, 0.0, 0.0});
    joint("right-top" + c, right, {0.5, 0.0, 0.0}, across, {0.0, 0.5, 0.0});
    previous = across;
  }
  model.add(sp::Gravity("gravity", hinged ? Vector3d(0.0, -9.81, 0.0) : Vector3d(0.0, 0.0, -9.81)));
  return model;
}

namespace pl = odyn::planar;
using PlanarModel = pl::Model<pl::Revolute, pl::Gravity>;

/// revolute-chain's links in the plane: hinged end to end along x, gravity along -y.
PlanarModel planar_chain(int n) {
  PlanarModel model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < n; ++i) {
    const odyn::BodyId body = model.add_body(pl::Body{.name = "link" + std::to_string(i),
                                                      .mass = 1.0,
                                                      .inertia = 1.0 / 12.0,
                                                      .position = {0.5 + i, 0.0}});
    const Eigen::Vector2d on_previous(previous.is_ground() ? 0.0 : 0.5, 0.0);
    model.add(pl::Revolute("joint" + std::to_string(i), previous, {on_previous}, body,
                           {Eigen::Vector2d(-0.5, 0.0)}));
    previous = body;
  }
  model.add(pl::Gravity("gravity", {0.0, -9.81}));
  return model;
}

struct Row {
  std::string name;
  int bodies = 0, equations = 0;
  double setup_s = 0.0, assembly_s = 0.0, step_s = 0.0, peak_rss_mb = 0.0;
  long steps = 0;
  double newton_per_step = 0.0, factorizations_per_step = 0.0;
  std::string status = "ok";
};

void newton_per_step_of(Row& row, const odyn::IntegratorStatistics& statistics) {
  const double steps = static_cast<double>(std::max(1L, statistics.steps));
  row.newton_per_step = static_cast<double>(statistics.newton_iterations) / steps;
  row.factorizations_per_step = static_cast<double>(statistics.factorizations) / steps;
}

/// Times `work` in blocks of at least 20 calls and 30 ms; the median of 5 blocks, per call.
template <class Work>
double median_time(Work&& work, long& calls) {
  for (int k = 0; k < 3; ++k) work();
  int block = 20;
  std::vector<double> per_call;
  for (int repeat = 0; repeat < 5; ++repeat) {
    const auto t0 = Clock::now();
    for (int k = 0; k < block; ++k) work();
    const double elapsed = seconds_since(t0);
    per_call.push_back(elapsed / block);
    calls += block;
    if (repeat == 0 && elapsed < 0.03)
      block = std::min(2000, static_cast<int>(block * 0.03 / elapsed) + 1);
  }
  std::sort(per_call.begin(), per_call.end());
  return per_call[per_call.size() / 2];
}

/// The model with generalized-alpha at h = step (absolute coordinates, or joint coordinates
/// with JointGeneralizedAlpha): setup (assembly and the integrator) and the time per step.
template <class Integrator, class Model>
Row measure(const std::string& name, const Model& model) {
  Row row;
  row.name = name;
  row.bodies = model.num_bodies();
  row.equations = model.num_equations();
  try {
    odyn::Workspace<Model> ws(model);
    const auto start = Clock::now();
    odyn::assemble(model, ws);
    row.assembly_s = seconds_since(start);
    Integrator integrator(model, ws);
    row.setup_s = seconds_since(start);
    // As simulate() steps: a step that fails to converge is cut (advance_to), so step_s is
    // the time per h of simulated time.
    odyn::StepCut cut;
    row.step_s = median_time(
        [&] {
          odyn::advance_to(model, ws, integrator, integrator.time() + step, step, 1e-12, &cut);
        },
        row.steps);
    newton_per_step_of(row, integrator.statistics());
    integrator.refresh_blocks();  // in joint coordinates, fills in the workspace's q
    if (!ws.q.allFinite()) row.status = "non-finite state";
  } catch (const std::exception& e) {
    row.status = std::string("failed: ") + e.what();
    std::replace(row.status.begin(), row.status.end(), ',', ';');
  }
  row.peak_rss_mb = peak_rss_mb();
  return row;
}

/// The model in joint coordinates: setup (assembly and the tree) and one forward-dynamics
/// evaluation at the start, as each stage of an explicit integrator makes it.
template <class Model>
Row measure_joint(const std::string& name, const Model& model) {
  Row row;
  row.name = name;
  row.bodies = model.num_bodies();
  try {
    odyn::Workspace<Model> ws(model);
    const auto start = Clock::now();
    odyn::assemble(model, ws);
    row.assembly_s = seconds_since(start);
    odyn::JointCoordinates<Model> coordinates(model, ws);
    row.setup_s = seconds_since(start);
    row.equations = static_cast<int>(coordinates.num_equations());
    Eigen::VectorXd y(coordinates.num_positions() + coordinates.num_velocities());
    coordinates.read_state(y);
    bool ok = true;
    row.step_s = median_time(
        [&] {
          coordinates.load(0.0, y);
          coordinates.evaluate_constraints();
          ok = coordinates.factorize() && coordinates.solve_accelerations() && ok;
        },
        row.steps);
    if (!ok) row.status = "singular";
  } catch (const std::exception& e) {
    row.status = std::string("failed: ") + e.what();
    std::replace(row.status.begin(), row.status.end(), ',', ';');
  }
  row.peak_rss_mb = peak_rss_mb();
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "scaling.csv";
  int min_n = 1, max_n = 4096;
  std::vector<std::string> only;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--out" && i + 1 < argc)
      out = argv[++i];
    else if (arg == "--min-n" && i + 1 < argc)
      min_n = std::atoi(argv[++i]);
    else if (arg == "--max-n" && i + 1 < argc)
      max_n = std::atoi(argv[++i]);
    else if (arg == "--case" && i + 1 < argc)
      only.emplace_back(argv[++i]);
    else if (arg == "--quick")
      max_n = 64;
    else {
      std::fprintf(
          stderr,
          "usage: scaling [--out FILE.csv] [--min-n N] [--max-n N] [--case NAME]... [--quick]\n");
      return 2;
    }
  }
  const std::vector<std::pair<std::string, std::function<Model(int)>>> cases = {
      {"spherical-chain", [](int n) { return chain(n, Joint::ball, false); }},
      {"spherical-chain-moving", [](int n) { return chain(n, Joint::ball, false, true); }},
      {"spherical-chain-springs", [](int n) { return chain(n, Joint::ball, true); }},
      {"revolute-chain", [](int n) { return chain(n, Joint::hinge, false); }},
      {"binary-tree", [](int n) { return binary_tree(n); }},
      {"four-bar-ladder", [](int n) { return four_bar_ladder(n); }},
      {"four-bar-ladder-hinged", [](int n) { return four_bar_ladder(n, true); }},
      {"spherical-chain-joint", [](int n) { return chain(n, Joint::ball, false); }},
      {"revolute-chain-joint", [](int n) { return chain(n, Joint::hinge, false); }},
      {"binary-tree-joint", [](int n) { return binary_tree(n); }},
      {"four-bar-ladder-joint", [](int n) { return four_bar_ladder(n); }},
      {"spherical-chain-joint-alpha", [](int n) { return chain(n, Joint::ball, false); }},
      {"spherical-chain-moving-joint-alpha",
       [](int n) { return chain(n, Joint::ball, false, true); }},
  };
  const std::vector<std::pair<std::string, std::function<PlanarModel(int)>>> planar_cases = {
      {"planar-revolute-chain", planar_chain},
      {"planar-revolute-chain-joint", planar_chain},
  };
  std::ofstream csv(out);
  csv << "case,N,equations,setup_s,assembly_s,step_s,steps,newton_per_step,"
         "factorizations_per_step,peak_rss_mb,status\n";
  std::printf("%-24s %6s %7s %10s %10s %10s %6s %6s %8s  %s\n", "case", "N", "eqs", "setup ms",
              "assem ms", "step ms", "newton", "facts", "RSS MB", "status");
  const auto run = [&]<class M>(const std::string& name, const std::function<M(int)>& build) {
    if (!only.empty() && std::find(only.begin(), only.end(), name) == only.end()) return;
    for (int n = 1; n <= max_n; n *= 2) {
      if (n < min_n) continue;
      const bool ladder = name.starts_with("four-bar-ladder");
      const bool joint = name.ends_with("-joint");
      if (ladder && (n < 3 || (joint && n > 256))) continue;
      const M model = build(ladder ? 3 * std::max(1, n / 3) : n);
      const Row row = joint ? measure_joint(name, model)
                      : name.ends_with("-alpha")
                          ? measure<odyn::JointGeneralizedAlpha<M>>(name, model)
                          : measure<odyn::GeneralizedAlpha<M>>(name, model);
      csv << row.name << ',' << row.bodies << ',' << row.equations << ',' << row.setup_s << ','
          << row.assembly_s << ',' << row.step_s << ',' << row.steps << ',' << row.newton_per_step
          << ',' << row.factorizations_per_step << ',' << row.peak_rss_mb << ',' << row.status
          << '\n';
      csv.flush();
      std::printf("%-24s %6d %7d %10.3f %10.3f %10.4f %6.2f %6.2f %8.0f  %s\n", row.name.c_str(),
                  row.bodies, row.equations, 1e3 * row.setup_s, 1e3 * row.assembly_s,
                  1e3 * row.step_s, row.newton_per_step, row.factorizations_per_step,
                  row.peak_rss_mb, row.status.c_str());
      std::fflush(stdout);
    }
  };
  for (const auto& [name, build] : cases) run(name, build);
  for (const auto& [name, build] : planar_cases) run(name, build);
}
