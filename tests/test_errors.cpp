// Bad input is reported by a specific exception type whose message names the element at fault
// and says what is wrong; nothing crashes, and a failed call leaves the model usable.

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

// Own namespace: the test files may be compiled together in one unity translation unit.
namespace test_errors {

namespace {

namespace sp = odyn::spatial;
using Model = sp::DefaultModel;
using Workspace = odyn::Workspace<Model>;
using Eigen::Vector3d;
using odyn::BodyId;
constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();

/// Matches an odyn exception whose element() (if it has one) and message name `element` and
/// whose message contains every one of `words` (case-sensitive).
template <class Exception>
class Describes : public Catch::MatcherBase<Exception> {
 public:
  Describes(std::string element, std::vector<std::string> words)
      : element_(std::move(element)), words_(std::move(words)) {}

  bool match(const Exception& e) const override {
    const std::string message = e.what();
    if constexpr (requires { e.element(); })
      if (e.element().find(element_) == std::string::npos) return false;
    if (message.find(element_) == std::string::npos) return false;
    for (const std::string& word : words_)
      if (message.find(word) == std::string::npos) return false;
    return true;
  }

  std::string describe() const override {
    std::string text = "names '" + element_ + "' and mentions";
    for (const std::string& word : words_) text += " '" + word + "'";
    return text;
  }

 private:
  std::string element_;
  std::vector<std::string> words_;
};

using ModelErrorAbout = Describes<odyn::ModelError>;
using AssemblyErrorAbout = Describes<odyn::AssemblyError>;
using SolverErrorAbout = Describes<odyn::SolverError>;

sp::Body good_body(const std::string& name, const Vector3d& position = Vector3d::Zero()) {
  return {.name = name,
          .mass = 1.0,
          .inertia = sp::Body::principal(0.1, 0.2, 0.25),
          .position = position};
}

/// A body on a ball joint 1 m below the origin.
struct Bob {
  Model model;
  BodyId body;
  Bob() {
    body = model.add_body(good_body("bob", {0.0, 0.0, -1.0}));
    model.add(sp::Spherical("ball", odyn::ground, Vector3d::Zero(), body, {0.0, 0.0, 1.0}));
  }
};

odyn::DynamicsSettings short_run() {
  odyn::DynamicsSettings s;
  s.step = 1e-3;
  s.output_interval = 1e-2;
  s.t_end = 0.2;
  return s;
}

}  // namespace

/// add_body rejects `body` with a ModelError naming it and mentioning `words`; the model is left
/// as it was, so that the corrected body (same name) can be added afterwards.
void check_rejected(sp::Body body, const std::vector<std::string>& words) {
  Model model;
  REQUIRE_THROWS_MATCHES(model.add_body(body), odyn::ModelError, ModelErrorAbout(body.name, words));
  CHECK(model.num_bodies() == 0);
  REQUIRE_NOTHROW(model.add_body(good_body(body.name)));
}

TEST_CASE("Bodies: mass and inertia must be physical", "[errors]") {
  sp::Body body = good_body("link");
  SECTION("zero mass") {
    body.mass = 0.0;
    check_rejected(body, {"mass", "positive", "got 0 kg"});
  }
  SECTION("negative mass") {
    body.mass = -2.0;
    check_rejected(body, {"mass", "positive", "got -2 kg"});
  }
  SECTION("NaN mass") {
    body.mass = not_a_number;
    check_rejected(body, {"mass", "positive"});
  }
  SECTION("inertia not positive definite") {
    body.inertia = sp::Body::principal(1.0, -1.0, 1.0);
    check_rejected(body, {"inertia", "positive definite", "-1"});
  }
  SECTION("singular inertia that no point mass or slender rod has") {
    body.inertia = sp::Body::principal(1.0, 1.0, -1e-3);
    check_rejected(body, {"inertia", "positive definite", "slender rod"});
  }
  SECTION("inertia violating the triangle inequality") {
    body.inertia = sp::Body::principal(1.0, 1.0, 3.0);
    check_rejected(body, {"triangle inequality", "1 1 3"});
  }
  SECTION("triangle inequality violated by a rotated tensor") {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(0.8, Vector3d(1.0, 2.0, -1.0).normalized()).toRotationMatrix();
    body.inertia = r * sp::Body::principal(3.0, 1.0, 1.0) * r.transpose();
    check_rejected(body, {"triangle inequality"});
  }
  SECTION("inertia not symmetric") {
    body.inertia(0, 1) = 0.05;
    check_rejected(body, {"symmetric"});
  }
  SECTION("NaN in the inertia") {
    body.inertia(2, 2) = not_a_number;
    check_rejected(body, {"inertia", "non-finite"});
  }
  SECTION("NaN in the position") {
    body.position.y() = not_a_number;
    check_rejected(body, {"initial pose", "NaN"});
  }
  SECTION("NaN in the orientation") {
    body.orientation.w() = not_a_number;
    check_rejected(body, {"initial pose", "NaN"});
  }
  SECTION("zero quaternion") {
    body.orientation.coeffs().setZero();
    check_rejected(body, {"quaternion", "zero length"});
  }
  SECTION("NaN in the linear velocity") {
    body.linear_velocity.x() = not_a_number;
    check_rejected(body, {"initial velocity", "NaN"});
  }
  SECTION("infinite angular velocity") {
    body.angular_velocity.z() = std::numeric_limits<double>::infinity();
    check_rejected(body, {"initial velocity", "infinity"});
  }
}

TEST_CASE("Bodies: limiting but physical inertias are accepted", "[errors]") {
  Model model;
  // A thin plate: J3 = J1 + J2 exactly.
  REQUIRE_NOTHROW(model.add_body(
      {.name = "plate", .mass = 1.0, .inertia = sp::Body::principal(1.0, 2.0, 3.0)}));
  // Products of inertia, positive definite and within the triangle inequality.
  Eigen::Matrix3d inertia = sp::Body::principal(2.0, 2.5, 3.0);
  inertia(0, 1) = inertia(1, 0) = 0.3;
  REQUIRE_NOTHROW(model.add_body({.name = "bracket", .mass = 1.0, .inertia = inertia}));
}

TEST_CASE("NaN written into a workspace's state: assembly refuses it", "[errors]") {
  Bob bob;
  Workspace ws(bob.model);
  SECTION("position") {
    ws.q[2] = not_a_number;
  }
  SECTION("velocity") {
    ws.v[4] = not_a_number;
  }
  REQUIRE_THROWS_MATCHES(odyn::assemble(bob.model, ws), odyn::AssemblyError,
                         AssemblyErrorAbout("bob", {"initial state", "NaN"}));
}

TEST_CASE("NaN written into a workspace's state: the message names the body", "[errors]") {
  Bob bob;
  Workspace ws(bob.model);
  ws.v[4] = not_a_number;
  REQUIRE_THROWS_MATCHES(odyn::assemble(bob.model, ws), odyn::AssemblyError,
                         AssemblyErrorAbout("bob", {"NaN"}));
}

TEST_CASE("Joint frames: axes, references and points", "[errors]") {
  const BodyId body{1};
  const Vector3d z = Vector3d::UnitZ();
  SECTION("zero axis on body a") {
    REQUIRE_THROWS_MATCHES(
        sp::Revolute("elbow", odyn::ground, sp::JointFrame{{0, 0, 0}, Vector3d::Zero()}, body,
                     sp::JointFrame{}),
        odyn::ModelError, ModelErrorAbout("elbow", {"axis on body a", "non-zero", "(0 0 0)"}));
  }
  SECTION("zero axis on body b") {
    REQUIRE_THROWS_MATCHES(sp::Cylindrical("sleeve", odyn::ground, sp::JointFrame{}, body,
                                           sp::JointFrame{{0, 0, 0}, Vector3d::Zero()}),
                           odyn::ModelError, ModelErrorAbout("sleeve", {"axis on body b"}));
  }
  SECTION("NaN axis") {
    REQUIRE_THROWS_MATCHES(
        sp::Translational("slide", odyn::ground, sp::JointFrame{{0, 0, 0}, {not_a_number, 0, 1}},
                          body, sp::JointFrame{}),
        odyn::ModelError, ModelErrorAbout("slide", {"axis on body a"}));
  }
  SECTION("reference parallel to the axis") {
    REQUIRE_THROWS_MATCHES(sp::Fixed("weld", odyn::ground, sp::JointFrame{{0, 0, 0}, z, -3.0 * z},
                                     body, sp::JointFrame{}),
                           odyn::ModelError,
                           ModelErrorAbout("weld", {"reference", "body a", "parallel"}));
  }
  SECTION("NaN point") {
    REQUIRE_THROWS_MATCHES(
        sp::Spherical("ball", odyn::ground, {0, not_a_number, 0}, body, {0, 0, 0}),
        odyn::ModelError, ModelErrorAbout("ball", {"point on body a"}));
  }
}

TEST_CASE("Joints: bodies, names and the initial pose", "[errors]") {
  Model model;
  const BodyId arm = model.add_body(good_body("arm"));
  const BodyId hand = model.add_body(good_body("hand", {1.0, 0.0, 0.0}));
  const Vector3d z = Vector3d::UnitZ();
  const int equations = model.num_equations();

  SECTION("a joint between a body and itself") {
    REQUIRE_THROWS_MATCHES(
        model.add(sp::Revolute("wrist", arm, sp::JointFrame{}, arm, sp::JointFrame{})),
        odyn::ModelError, ModelErrorAbout("wrist", {"'arm'", "itself"}));
  }
  SECTION("an unknown body") {
    REQUIRE_THROWS_MATCHES(
        model.add(sp::Spherical("ball", arm, Vector3d::Zero(), BodyId{42}, Vector3d::Zero())),
        odyn::ModelError, ModelErrorAbout("ball", {"42", "not in the model", "2 moving bodies"}));
  }
  SECTION("a negative body number") {
    REQUIRE_THROWS_MATCHES(
        model.add(sp::PointForce("push", BodyId{-1}, Vector3d::Zero(), Vector3d(1.0, 0.0, 0.0))),
        odyn::ModelError, ModelErrorAbout("push", {"-1", "not in the model"}));
  }
  SECTION("parallel axes in a universal joint") {
    // The cross's two axes along global z at the initial pose: the cross is degenerate.
    REQUIRE_THROWS_MATCHES(model.add(sp::Universal("cardan", arm, sp::JointFrame{{0.5, 0, 0}, z},
                                                   hand, sp::JointFrame{{-0.5, 0, 0}, -z})),
                           odyn::ModelError, ModelErrorAbout("cardan", {"parallel", "axes"}));
  }
  SECTION("a distance constraint whose points coincide and no length given") {
    REQUIRE_THROWS_MATCHES(model.add(sp::Distance("rod", arm, {0.5, 0, 0}, hand, {-0.5, 0, 0})),
                           odyn::ModelError,
                           ModelErrorAbout("rod", {"coincide", "positive length"}));
  }
  SECTION("a non-finite distance") {
    REQUIRE_THROWS_MATCHES(
        sp::Distance("rod", arm, Vector3d::Zero(), hand, Vector3d::Zero(), not_a_number),
        odyn::ModelError, ModelErrorAbout("rod", {"length", "finite"}));
  }
  SECTION("a driver without its motion's derivatives") {
    odyn::Motion motion = odyn::Motion::constant_velocity(1.0);
    motion.acceleration = nullptr;
    REQUIRE_THROWS_MATCHES(
        sp::RevoluteDriver("motor", arm, sp::JointFrame{}, hand, sp::JointFrame{}, motion),
        odyn::ModelError, ModelErrorAbout("motor", {"acceleration"}));
  }
  SECTION("an empty force function") {
    REQUIRE_THROWS_MATCHES(
        sp::PointForce("push", arm, Vector3d::Zero(), sp::PointForce::Function{}), odyn::ModelError,
        ModelErrorAbout("push", {"empty"}));
  }
  SECTION("a negative free length") {
    REQUIRE_THROWS_MATCHES(
        sp::Tsda("spring", arm, Vector3d::Zero(), hand, Vector3d::Zero(), {.free_length = -1.0}),
        odyn::ModelError, ModelErrorAbout("spring", {"free length"}));
  }
  SECTION("a non-finite gravity") {
    REQUIRE_THROWS_MATCHES(sp::Gravity("gravity", {0.0, 0.0, not_a_number}), odyn::ModelError,
                           ModelErrorAbout("gravity", {"not finite"}));
  }
  // None of the rejected elements left rows or a name behind.
  CHECK(model.num_equations() == equations);
  REQUIRE_NOTHROW(model.add(sp::Spherical("ball", arm, {0.5, 0, 0}, hand, {-0.5, 0, 0})));
  CHECK(model.num_equations() == equations + 3);
}

TEST_CASE("Names must be unique", "[errors]") {
  Model model;
  const BodyId link = model.add_body(good_body("link"));
  model.add(sp::Spherical("pin", odyn::ground, Vector3d::Zero(), link, Vector3d::Zero()));
  SECTION("two bodies") {
    REQUIRE_THROWS_MATCHES(model.add_body(good_body("link")), odyn::ModelError,
                           ModelErrorAbout("link", {"already used", "unique"}));
  }
  SECTION("a body named like the ground") {
    REQUIRE_THROWS_MATCHES(model.add_body(good_body("ground")), odyn::ModelError,
                           ModelErrorAbout("ground", {"already used"}));
  }
  SECTION("a body named like an element") {
    REQUIRE_THROWS_MATCHES(model.add_body(good_body("pin")), odyn::ModelError,
                           ModelErrorAbout("pin", {"already used"}));
  }
  SECTION("two elements") {
    REQUIRE_THROWS_MATCHES(
        model.add(sp::Spherical("pin", odyn::ground, Vector3d::Zero(), link, Vector3d::Zero())),
        odyn::ModelError, ModelErrorAbout("pin", {"already used"}));
  }
  SECTION("an element named like a body") {
    REQUIRE_THROWS_MATCHES(model.add(sp::Gravity("link", {0.0, 0.0, -9.81})), odyn::ModelError,
                           ModelErrorAbout("link", {"already used"}));
  }
  SECTION("an empty name") {
    REQUIRE_THROWS_MATCHES(model.add_body(good_body("")), odyn::ModelError,
                           ModelErrorAbout("(unnamed)", {"needs a name"}));
  }
  SECTION("looking up unknown or mistyped names") {
    REQUIRE_THROWS_MATCHES(model.body("lnik"), odyn::ModelError,
                           ModelErrorAbout("lnik", {"no body"}));
    REQUIRE_THROWS_MATCHES(model.handle<sp::Revolute>("pin"), odyn::ModelError,
                           ModelErrorAbout("pin", {"another type"}));
  }
  CHECK(model.num_bodies() == 1);
  CHECK(model.num_equations() == 3);
}

/// A door on two coaxial hinges about z (points 1 m above and below its centre of mass): five
/// of the second hinge's equations repeat the first's. `gap` moves the lower hinge's ground
/// point down, so that the two hinges cannot both hold.
Model two_hinged_door(double gap = 0.0) {
  Model model;
  const BodyId door = model.add_body(good_body("door"));
  model.add(sp::Revolute("upper hinge", odyn::ground, sp::JointFrame{{0, 0, 1}}, door,
                         sp::JointFrame{{0, 0, 1}}));
  model.add(sp::Revolute("lower hinge", odyn::ground, sp::JointFrame{{0, 0, -1 - gap}}, door,
                         sp::JointFrame{{0, 0, -1}}));
  return model;
}

TEST_CASE("Over-constrained mechanism: the redundant joints are named, and it runs", "[errors]") {
  Model model = two_hinged_door();
  Workspace ws(model);
  // The check for a model that must be free of redundancy still names them.
  odyn::assemble(model, ws);
  REQUIRE_THROWS_MATCHES(odyn::require_independent_constraints(model, ws), odyn::ModelError,
                         ModelErrorAbout("hinge", {"redundant", "upper hinge", "lower hinge"}));
  // A run goes on with the minimum-norm multipliers and reports the redundant equations: five,
  // all of the hinges (which of the two is a choice).
  Workspace run(model);
  run.v[5] = 2.0;  // swinging about the hinge axis at 2 rad/s
  odyn::RunSummary summary;
  REQUIRE_NOTHROW(summary = odyn::simulate_with<odyn::GeneralizedAlpha>(model, run, short_run(),
                                                                        [](const Workspace&) {}));
  REQUIRE(summary.redundant_equations.size() == 5);
  for (const odyn::RedundantEquation& e : summary.redundant_equations) {
    INFO(e.text());
    CHECK((e.joint == "upper hinge" || e.joint == "lower hinge"));
    CHECK(e.equation >= 0);
    CHECK(e.equation < 5);
    CHECK(model.constraint_name(e.row) == e.joint);
    CHECK_THAT(e.text(), Catch::Contains(e.joint) && Catch::Contains("equation"));
  }
  // The door swings on: 0.4 rad in 0.2 s, still on its axis; no force acts, so the hinges
  // carry nothing (the minimum-norm multipliers are zero, not an arbitrary self-stress).
  CHECK(run.t == Approx(0.2));
  CHECK(2.0 * std::atan2(run.q[6], run.q[3]) == Approx(0.4).epsilon(1e-9));
  CHECK(run.q.head<3>().norm() < 1e-10);
  CHECK(summary.max_position_residual < 1e-10);
  CHECK(run.lambda.norm() < 1e-8);
}

TEST_CASE("Over-constrained mechanism whose constraints contradict each other", "[errors]") {
  // The lower hinge's ground point 0.25 m too low: the door cannot meet both. The assembly
  // names the hinges instead of running with a least-squares compromise.
  Model model = two_hinged_door(0.25);
  Workspace ws(model);
  REQUIRE_THROWS_MATCHES(
      odyn::simulate_with<odyn::GeneralizedAlpha>(model, ws, short_run(), [](const Workspace&) {}),
      odyn::AssemblyError,
      AssemblyErrorAbout(
          "hinge", {"could not be satisfied", "largest residual", "upper hinge", "lower hinge"}));
}

TEST_CASE("Assembly that cannot converge", "[errors]") {
  // An arm on a hinge about y at the origin; its tip (1 m from the hinge) is tied by a 1 m rod to
  // a ground point 5 m away, which the tip cannot come closer to than 4 m.
  Model model;
  const BodyId arm = model.add_body(good_body("arm", {1.0, 0.0, 0.0}));
  model.add(sp::Revolute("hinge", odyn::ground, sp::JointFrame{{0, 0, 0}, Vector3d::UnitY()}, arm,
                         sp::JointFrame{{-1, 0, 0}, Vector3d::UnitY()}));
  model.add(sp::Distance("rod", odyn::ground, {5.0, 0.0, 0.0}, arm, {0.0, 0.0, 0.0}, 1.0));
  Workspace ws(model);
  try {
    odyn::assemble(model, ws);
    FAIL("assembly of an impossible mechanism succeeded");
  } catch (const odyn::AssemblyError& e) {
    const std::string message = e.what();
    INFO(message);
    CHECK((e.element() == "hinge" || e.element() == "rod"));
    CHECK_THAT(message, Catch::Contains("'" + e.element() + "'") &&
                            Catch::Contains("largest residual") &&
                            Catch::Contains("50 Newton iterations"));
    // The residual quoted is the one left in the workspace.
    CHECK_THAT(message, Catch::Contains(odyn::to_text(ws.phi.cwiseAbs().maxCoeff())));
    CHECK(ws.phi.cwiseAbs().maxCoeff() > 0.1);
  }
}

// The minimum-norm steps spread the violation over both joints: the hinge ends up with the
// largest residual (1.99 m against the rod's 1.52), so it is the element named, and the message
// lists the rod as unsatisfied too.
TEST_CASE("Assembly that cannot converge names every unsatisfied joint", "[errors]") {
  Model model;
  const BodyId arm = model.add_body(good_body("arm", {1.0, 0.0, 0.0}));
  model.add(sp::Revolute("hinge", odyn::ground, sp::JointFrame{{0, 0, 0}, Vector3d::UnitY()}, arm,
                         sp::JointFrame{{-1, 0, 0}, Vector3d::UnitY()}));
  model.add(sp::Distance("rod", odyn::ground, {5.0, 0.0, 0.0}, arm, {0.0, 0.0, 0.0}, 1.0));
  Workspace ws(model);
  REQUIRE_THROWS_MATCHES(
      odyn::assemble(model, ws), odyn::AssemblyError,
      AssemblyErrorAbout("hinge", {"largest residual", "also unsatisfied: 'rod'"}));
}

TEST_CASE("A force that returns NaN during a run", "[errors]") {
  Bob bob;
  bob.model.add(
      sp::PointForce("kick", bob.body, Vector3d::Zero(), [](double t, const odyn::Spatial::Frame&) {
        return t > 0.05 ? Vector3d(not_a_number, 0.0, 0.0) : Vector3d(1.0, 0.0, 0.0);
      }));
  bob.model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  Workspace ws(bob.model);
  odyn::DynamicsSettings settings = short_run();
  odyn::RunSummary partial;  // what the run counted before it failed
  settings.partial = &partial;
  double last_output = -1.0;
  long outputs = 0;
  try {
    odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings, [&](const Workspace& w) {
      last_output = w.t;
      ++outputs;
    });
    FAIL("the run went on with a NaN force");
  } catch (const odyn::SolverError& e) {
    INFO(e.what());
    // The first step that evaluates the force after t = 0.05 fails.
    CHECK(e.time() > 0.05);
    CHECK(e.time() <= 0.05 + settings.step + 1e-12);
    CHECK_THAT(std::string(e.what()),
               Catch::Contains("'kick'") && Catch::Contains("NaN") && Catch::Contains("t = 0.05"));
  }
  CHECK(last_output == Approx(0.05));
  // Fixed steps of 1 ms, every one accepted up to t = 0.05; outputs at 0, 0.01, ..., 0.05.
  CHECK(partial.statistics.steps == 50);
  CHECK(partial.outputs == outputs);
  CHECK(outputs == 6);
  // The workspace is back at the last good state, not filled with NaN.
  CHECK(ws.q.allFinite());
  CHECK(ws.v.allFinite());
  CHECK(ws.t == Approx(0.05).margin(settings.step));
}

TEST_CASE("A force far too stiff for the step", "[errors]") {
  // A 1e12 N/m spring with no Newton Jacobian on a 1 kg bob, h = 1 ms: omega h = 1e3, and the
  // Newton iteration, which does not see the stiffness, diverges in the first step.
  Bob bob;
  bob.model.add(sp::PointForce("stiff spring", bob.body, Vector3d::Zero(),
                               [](double, const odyn::Spatial::Frame& f) {
                                 return Vector3d(-1e12 * f.position.x(), 0.0, 0.0);
                               }));
  Workspace ws(bob.model);
  ws.v[0] = 1.0;  // moving, so the spring is stretched in the first step
  const odyn::DynamicsSettings settings = short_run();
  try {
    odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings, [](const Workspace&) {});
    FAIL("the run went on");
  } catch (const odyn::SolverError& e) {
    INFO(e.what());
    // The step was cut to 1/16 (advance_to), where omega h is still 60, before the run stopped.
    CHECK(e.time() == Approx(settings.step / 16));
    CHECK_THAT(std::string(e.what()), Catch::Contains("did not converge") &&
                                          Catch::Contains("step size") &&
                                          Catch::Contains("cut to 1/16"));
  }
  CHECK(ws.q.allFinite());
  CHECK(ws.t == 0.0);
}

TEST_CASE("A force far too stiff for the step: the message names the force", "[errors]") {
  Bob bob;
  bob.model.add(sp::PointForce("stiff spring", bob.body, Vector3d::Zero(),
                               [](double, const odyn::Spatial::Frame& f) {
                                 return Vector3d(-1e12 * f.position.x(), 0.0, 0.0);
                               }));
  Workspace ws(bob.model);
  ws.v[0] = 1.0;
  REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, short_run(),
                                                                     [](const Workspace&) {}),
                         odyn::SolverError, SolverErrorAbout("stiff spring", {"converge"}));
}

TEST_CASE("Assembly reports how far it moved each body; a run warns above a threshold",
          "[errors]") {
  // A block welded to the ground at (1, 0, 0) with the global axes, given 2 mm off and turned
  // 0.01 rad about an oblique axis: assembly must move it by exactly that much. The bob hangs
  // where its ball joint wants it and stays.
  Bob bob;
  sp::Body block = good_body("block", {1.0, 0.002, 0.0});
  const double turn = 0.01;
  block.orientation = Eigen::AngleAxisd(turn, Vector3d(1.0, 2.0, 2.0).normalized());
  const BodyId id = bob.model.add_body(block);
  const sp::JointFrame global_axes{
      .point = Vector3d::Zero(), .axis = Vector3d::UnitZ(), .reference = Vector3d::UnitX()};
  bob.model.add(sp::Fixed(
      "weld", odyn::ground,
      {.point = {1.0, 0.0, 0.0}, .axis = Vector3d::UnitZ(), .reference = Vector3d::UnitX()}, id,
      global_axes));
  Workspace ws(bob.model);
  const odyn::AssemblyReport report = odyn::assemble(bob.model, ws);
  REQUIRE(report.moved_bodies.size() == 1);
  CHECK(report.moved_bodies[0].body == "block");
  CHECK(report.moved_bodies[0].translation == Approx(0.002).epsilon(1e-9));
  CHECK(report.moved_bodies[0].rotation == Approx(turn).epsilon(1e-9));

  odyn::DynamicsSettings settings = short_run();
  settings.t_end = 0.01;
  Workspace run(bob.model);
  const odyn::RunSummary warned = odyn::simulate_with<odyn::GeneralizedAlpha>(
      bob.model, run, settings, [](const Workspace&) {});
  REQUIRE(warned.warnings.size() == 1);
  CHECK(warned.warnings[0].kind == "assembly");
  CHECK_THAT(warned.warnings[0].text, Catch::Contains("'block' by 0.002 m and 0.01 rad") &&
                                          Catch::Contains("1 body") && !Catch::Contains("'bob'"));
  // A rough pose on purpose: thresholds above the move, no warning.
  settings.assembly.warn_translation = 0.003;
  settings.assembly.warn_rotation = 0.02;
  Workspace quiet(bob.model);
  CHECK(
      odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, quiet, settings, [](const Workspace&) {
      }).warnings.empty());
}

TEST_CASE("A tolerance below what double precision delivers is raised, with a warning",
          "[errors]") {
  Bob bob;
  odyn::DynamicsSettings settings = short_run();
  settings.t_end = 0.02;
  settings.generalized_alpha.adaptive = true;
  auto run = [&](double rtol) {
    settings.rtol = rtol;
    Workspace ws(bob.model);
    ws.v[0] = 1.0;  // swinging about the ball joint at 1 m/s
    return odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings,
                                                       [](const Workspace&) {});
  };
  const odyn::RunSummary raised = run(1e-16);
  REQUIRE(raised.warnings.size() == 1);
  CHECK(raised.warnings[0].kind == "tolerance");
  CHECK_THAT(raised.warnings[0].text,
             Catch::Contains("rtol 1e-16") && Catch::Contains(odyn::to_text(odyn::rtol_floor)));
  // The run is the one at the floor, step for step.
  const odyn::RunSummary at_floor = run(odyn::rtol_floor);
  CHECK(at_floor.warnings.empty());
  CHECK(raised.statistics.steps == at_floor.statistics.steps);
  CHECK(raised.statistics.steps > 10);
  // A fixed-step run does not use rtol: nothing to say.
  settings.generalized_alpha.adaptive = false;
  CHECK(run(1e-16).warnings.empty());
}

TEST_CASE("Run settings", "[errors]") {
  Bob bob;
  Workspace ws(bob.model);
  odyn::DynamicsSettings settings = short_run();
  SECTION("non-positive step") {
    settings.step = 0.0;
    REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings,
                                                                       [](const Workspace&) {}),
                           odyn::ModelError, ModelErrorAbout("dynamics", {"step"}));
  }
  SECTION("end before start") {
    ws.t = 1.0;
    REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings,
                                                                       [](const Workspace&) {}),
                           odyn::ModelError, ModelErrorAbout("dynamics", {"t_end"}));
  }
  SECTION("a step too short to advance time (it ran into NaN, blamed on an element)") {
    settings.step = 1e-300;
    REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings,
                                                                       [](const Workspace&) {}),
                           odyn::ModelError,
                           ModelErrorAbout("dynamics", {"1e-300", "time would not advance"}));
  }
  SECTION("an output interval too short to count (its count overflowed into one row)") {
    settings.output_interval = 1e-300;
    REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings,
                                                                       [](const Workspace&) {}),
                           odyn::ModelError,
                           ModelErrorAbout("dynamics", {"1e-300", "give a longer interval"}));
  }
  SECTION("rho_inf outside [0, 1]") {
    settings.generalized_alpha.rho_inf = 1.5;
    REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings,
                                                                       [](const Workspace&) {}),
                           odyn::ModelError, ModelErrorAbout("generalized-alpha", {"rho_inf"}));
  }
  SECTION("a model without moving bodies (it used to crash generalized-alpha)") {
    Model empty;
    Workspace empty_ws(empty);
    REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(empty, empty_ws, settings,
                                                                       [](const Workspace&) {}),
                           odyn::ModelError,
                           ModelErrorAbout("dynamics", {"no moving bodies", "add a body"}));
  }
  SECTION("rho_inf below 0.5 for HHT") {
    settings.integrator = "hht";
    settings.generalized_alpha.rho_inf = 0.3;
    REQUIRE_THROWS_MATCHES(odyn::simulate_with<odyn::GeneralizedAlpha>(bob.model, ws, settings,
                                                                       [](const Workspace&) {}),
                           odyn::ModelError, ModelErrorAbout("hht", {"rho_inf"}));
  }
}

}  // namespace test_errors
