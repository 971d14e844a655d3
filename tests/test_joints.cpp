// Every spatial constraint type against finite differences of its own Phi:
//   - each Jacobian block against central differences of Phi on the tangent space of the body's
//     configuration (translation global, rotation body frame: odyn::Spatial::integrate);
//   - Phi_t against central differences of Phi in time at fixed q;
//   - gamma against central differences in time of (Phi_q v + Phi_t) along a motion with constant
//     body velocities (v' = 0 in body coordinates), where d/dt (Phi_q v + Phi_t) = -gamma;
// and, after odyn::assemble from a slightly perturbed pose, |Phi| < 1e-12 together with the
// joint's geometric conditions written out independently from the body poses.

#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>

#include <odyn/odyn.hpp>

// Own namespace: the test files may be compiled together in one unity translation unit.
namespace test_joints {

namespace {

namespace sp = odyn::spatial;
using Model = sp::DefaultModel;
using Workspace = odyn::Workspace<Model>;
using odyn::BodyId;
using Space = odyn::Spatial;
using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

constexpr double kTime = 0.37;  // non-zero, so that the drivers' motions are not at their start

// Deterministic numbers in [-1, 1): std::mt19937's output is fixed by the standard (unlike the
// standard distributions), so every platform and compiler tests the same poses.
class Random {
 public:
  explicit Random(std::uint32_t seed) : engine_(seed) {}
  double uniform() { return 2.0 * (static_cast<double>(engine_()) / 4294967296.0) - 1.0; }
  // One draw per declarator: a call's arguments are evaluated in an order of the compiler's
  // choosing (g++ and Clang differ), which would change the poses.
  Vector3d vector(double scale) {
    const double x = uniform(), y = uniform(), z = uniform();
    return scale * Vector3d(x, y, z);
  }
  Vector3d direction() {
    for (;;) {
      const Vector3d d = vector(1.0);
      if (d.norm() > 0.3) return d.normalized();
    }
  }
  Quaterniond rotation() {
    const double w = uniform(), x = uniform(), y = uniform(), z = uniform();
    Quaterniond q(w, x, y, z);
    q.normalize();
    return q;
  }

 private:
  std::mt19937 engine_;
};

Vector3d perpendicular_to(const Vector3d& axis, const Vector3d& hint) {
  return (hint - hint.dot(axis) * axis).normalized();
}

/// A joint described in the global frame at an assembled pose, and the same joint in each body's
/// coordinates (what the user gives the library).
struct Scene {
  bool ground_a = false;
  // Assembled poses of body a (identity if ground) and body b.
  Vector3d x_a = Vector3d::Zero(), x_b = Vector3d::Zero();
  Quaterniond r_a = Quaterniond::Identity(), r_b = Quaterniond::Identity();
  // The joint, global: point, axis, reference, a second axis perpendicular to the first (for
  // the universal joint's cross) and a second point (for the distance constraint).
  Vector3d point, axis, reference, cross_axis, far_point;
  // Local frames (deliberately non-unit axes and references not perpendicular to the axis; the
  // library normalizes and projects them).
  sp::JointFrame on_a, on_b, on_b_cross, on_b_far;
  double length = 0.0;
};

sp::JointFrame local_frame(const Vector3d& x, const Quaterniond& r, const Vector3d& point,
                           const Vector3d& axis, const Vector3d& reference) {
  const Matrix3d rt = r.toRotationMatrix().transpose();
  sp::JointFrame f;
  f.point = rt * (point - x);
  f.axis = 1.7 * (rt * axis);                           // length does not matter
  f.reference = 0.8 * (rt * reference) + 0.3 * f.axis;  // only its part across the axis counts
  return f;
}

Scene make_scene(std::uint32_t seed, bool ground_a) {
  Random random(seed);
  Scene s;
  s.ground_a = ground_a;
  if (!ground_a) {
    s.x_a = random.vector(1.0);
    s.r_a = random.rotation();
  }
  s.x_b = random.vector(1.0);
  s.r_b = random.rotation();
  s.point = random.vector(0.8);
  s.axis = random.direction();
  s.reference = perpendicular_to(s.axis, random.direction());
  s.cross_axis = perpendicular_to(s.axis, random.direction());
  s.far_point = s.point + 0.9 * random.direction();
  s.length = (s.far_point - s.point).norm();
  s.on_a = local_frame(s.x_a, s.r_a, s.point, s.axis, s.reference);
  s.on_b = local_frame(s.x_b, s.r_b, s.point, s.axis, s.reference);
  s.on_b_cross = local_frame(s.x_b, s.r_b, s.point, s.cross_axis, s.axis);
  s.on_b_far = local_frame(s.x_b, s.r_b, s.far_point, s.axis, s.reference);
  return s;
}

// The constraint under test, built from a scene. The motions are smooth and non-trivial in all of
// their first three derivatives at kTime.
odyn::Motion harmonic_motion() {
  return odyn::Motion::harmonic(0.7, 3.0, 0.4, 0.2);
}
odyn::Motion polynomial_motion() {
  return odyn::Motion::polynomial({0.1, -0.3, 0.8, 0.5});
}

template <class E>
E make_joint(const Scene& s, BodyId a, BodyId b);
template <>
sp::Revolute make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Revolute("hinge", a, s.on_a, b, s.on_b);
}
template <>
sp::Translational make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Translational("slider", a, s.on_a, b, s.on_b);
}
template <>
sp::Spherical make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Spherical("ball", a, s.on_a.point, b, s.on_b.point);
}
template <>
sp::Universal make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Universal("cardan", a, s.on_a, b, s.on_b_cross);
}
template <>
sp::CvJoint make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::CvJoint("cv", a, s.on_a, b, s.on_b);
}
template <>
sp::Cylindrical make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Cylindrical("cylinder", a, s.on_a, b, s.on_b);
}
template <>
sp::Fixed make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Fixed("weld", a, s.on_a, b, s.on_b);
}
template <>
sp::Distance make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Distance("rod", a, s.on_a.point, b, s.on_b_far.point, s.length);
}
template <>
sp::InLine make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::InLine("in line", a, s.on_a, b, s.on_b);
}
template <>
sp::InPlane make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::InPlane("in plane", a, s.on_a, b, s.on_b);
}
template <>
sp::Orientation make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Orientation("orientation", a, s.on_a, b, s.on_b);
}
template <>
sp::ParallelAxes make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::ParallelAxes("parallel", a, s.on_a, b, s.on_b);
}
template <>
sp::Perpendicular make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::Perpendicular("perpendicular", a, s.on_a, b, s.on_b_cross);
}
template <>
sp::PlanarJoint make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::PlanarJoint("planar", a, s.on_a, b, s.on_b);
}
template <>
sp::RevoluteDriver make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::RevoluteDriver("angle driver", a, s.on_a, b, s.on_b, harmonic_motion());
}
template <>
sp::TranslationalDriver make_joint(const Scene& s, BodyId a, BodyId b) {
  return sp::TranslationalDriver("slide driver", a, s.on_a, b, s.on_b, polynomial_motion());
}

template <class E>
struct Built {
  Model model;
  odyn::Handle<E> handle;
  BodyId a, b;
};

/// The scene's joint between its two bodies, each moved away from its assembled pose by a random
/// global translation (components up to translation_offset) and a random body-frame rotation
/// vector (components up to rotation_offset), and given random velocities.
template <class E>
Built<E> build(const Scene& s, std::uint32_t seed, double translation_offset,
               double rotation_offset) {
  Random random(seed + 1000);
  Built<E> built;
  auto body = [&](const std::string& name, const Vector3d& x, const Quaterniond& r) {
    sp::Body body{.name = name, .mass = 1.3, .inertia = sp::Body::principal(0.2, 0.3, 0.4)};
    Space::Configuration q;
    q << x, r.w(), r.x(), r.y(), r.z();
    Space::Velocity offset;
    offset << random.vector(translation_offset), random.vector(rotation_offset);
    Space::integrate(Space::Configuration(q), offset, q);
    body.position = q.head<3>();
    body.orientation = Quaterniond(q[3], q[4], q[5], q[6]);
    body.linear_velocity = random.vector(2.0);
    body.angular_velocity = random.vector(3.0);
    return body;
  };
  built.a = s.ground_a ? odyn::ground : built.model.add_body(body("body a", s.x_a, s.r_a));
  built.b = built.model.add_body(body("body b", s.x_b, s.r_b));
  built.handle = built.model.add(make_joint<E>(s, built.a, built.b));
  return built;
}

template <class E>
using Vec = Eigen::Matrix<double, E::num_equations, 1>;

template <class E>
const odyn::BlocksOf<E>& blocks_of(const Workspace& ws, odyn::Handle<E> handle) {
  return std::get<Model::type_index<E>>(ws.blocks)[handle.index];
}

void evaluate(const Model& model, Workspace& ws) {
  odyn::update_frames(model, ws);
  odyn::evaluate_constraints(model, ws);
}

/// Phi_q v + Phi_t of one element, from its blocks at the workspace's state.
template <class E>
Vec<E> constraint_velocity(const Model& model, const Workspace& ws, odyn::Handle<E> handle) {
  const auto& blocks = blocks_of(ws, handle);
  Vec<E> rate = blocks.phi_t;
  for (int k = 0; k < E::num_bodies; ++k) {
    const BodyId body = model.element(handle).bodies()[k];
    if (!body.is_ground())
      rate += blocks.jacobian[k] * ws.v.segment<Space::nv>(Model::velocity_offset(body));
  }
  return rate;
}

/// Moves every body along its constant body velocity for a time dt (v' = 0).
void drift(const Model& model, Workspace& ws, double dt) {
  for (int b = 1; b <= model.num_bodies(); ++b) {
    const Space::Configuration q = ws.q.segment<Space::nq>((b - 1) * Space::nq);
    const Space::Velocity v = ws.v.segment<Space::nv>((b - 1) * Space::nv);
    Space::integrate(q, dt * v, ws.q.segment<Space::nq>((b - 1) * Space::nq));
  }
  ws.t += dt;
}

template <class Derived, class Other>
double relative_error(const Eigen::MatrixBase<Derived>& value,
                      const Eigen::MatrixBase<Other>& reference) {
  return (value - reference).cwiseAbs().maxCoeff() / std::max(1.0, reference.cwiseAbs().maxCoeff());
}

/// Checks one constraint element's Jacobian blocks, Phi_t and gamma against finite differences.
template <class E>
void check_derivatives(const Built<E>& built) {
  const Model& model = built.model;
  Workspace ws(model);
  ws.t = kTime;
  evaluate(model, ws);
  const odyn::BlocksOf<E> blocks = blocks_of(ws, built.handle);
  const int row = model.row(built.handle);
  // The element's rows land where model.row says.
  REQUIRE(ws.phi.segment<E::num_equations>(row) == blocks.phi);
  // A genuinely unassembled pose: the checks below are not helped by Phi = 0.
  CHECK(blocks.phi.norm() > 1e-3);

  auto phi_at = [&](const Workspace& state) {
    Workspace copy = state;
    evaluate(model, copy);
    return Vec<E>(blocks_of(copy, built.handle).phi);
  };

  // 1. Jacobian blocks: d Phi / d(tangent coordinates of body k).
  const double eps = 1e-6;
  for (int k = 0; k < E::num_bodies; ++k) {
    const BodyId body = model.element(built.handle).bodies()[k];
    if (body.is_ground()) continue;
    const int offset = Model::configuration_offset(body);
    Eigen::Matrix<double, E::num_equations, Space::nv> numeric;
    for (int i = 0; i < Space::nv; ++i) {
      Workspace plus = ws, minus = ws;
      const Space::Configuration q = ws.q.segment<Space::nq>(offset);
      Space::integrate(q, eps * Space::Velocity::Unit(i), plus.q.segment<Space::nq>(offset));
      Space::integrate(q, -eps * Space::Velocity::Unit(i), minus.q.segment<Space::nq>(offset));
      numeric.col(i) = (phi_at(plus) - phi_at(minus)) / (2.0 * eps);
    }
    INFO("body side " << k << "\nanalytic:\n" << blocks.jacobian[k] << "\nnumeric:\n" << numeric);
    CHECK(relative_error(blocks.jacobian[k], numeric) < 1e-6);
  }

  // 2. Phi_t: d Phi / dt at fixed configuration.
  {
    const double dt = 1e-6;
    Workspace later = ws, earlier = ws;
    later.t += dt;
    earlier.t -= dt;
    const Vec<E> numeric = (phi_at(later) - phi_at(earlier)) / (2.0 * dt);
    INFO("phi_t analytic " << blocks.phi_t.transpose() << "\nnumeric " << numeric.transpose());
    CHECK(relative_error(blocks.phi_t, numeric) < 1e-6);
  }

  // 3. The total rate along the motion: d Phi / dt = Phi_q v + Phi_t (Jacobian and Phi_t
  //    together, in the velocity coordinates the integrator uses).
  {
    const double dt = 1e-6;
    Workspace later = ws, earlier = ws;
    drift(model, later, dt);
    drift(model, earlier, -dt);
    const Vec<E> numeric = (phi_at(later) - phi_at(earlier)) / (2.0 * dt);
    const Vec<E> analytic = constraint_velocity(model, ws, built.handle);
    INFO("Phi-dot analytic " << analytic.transpose() << "\nnumeric " << numeric.transpose());
    CHECK(relative_error(analytic, numeric) < 1e-6);
  }

  // 4. gamma: with v' = 0, d/dt (Phi_q v + Phi_t) = -gamma.
  {
    odyn::evaluate_gamma(model, ws);
    const Vec<E> gamma = ws.gamma.segment<E::num_equations>(row);
    // The element's own gamma agrees with the assembled vector.
    REQUIRE(gamma == model.element(built.handle)
                         .gamma(odyn::InputOf<E>{
                             {&ws.frames[built.a.index], &ws.frames[built.b.index]}, ws.t}));
    const double dt = 1e-5;
    Workspace later = ws, earlier = ws;
    drift(model, later, dt);
    drift(model, earlier, -dt);
    evaluate(model, later);
    evaluate(model, earlier);
    const Vec<E> numeric = -(constraint_velocity(model, later, built.handle) -
                             constraint_velocity(model, earlier, built.handle)) /
                           (2.0 * dt);
    INFO("gamma analytic " << gamma.transpose() << "\nnumeric " << numeric.transpose());
    CHECK(relative_error(gamma, numeric) < 1e-5);
    CHECK(gamma.norm() > 1e-3);  // a meaningful check: the velocity terms are not all zero
  }

  // 5. Geometric stiffness: body k's block is d(J_k^T lambda)/d(tangent coordinates of k).
  if constexpr (odyn::HasGeometricStiffness<E>) {
    const Vec<E> lambda = Vec<E>::LinSpaced(E::num_equations, 3.0, -2.0);
    odyn::GeometricStiffness<Space, E::num_bodies> analytic;
    for (auto& block : analytic) block.setZero();
    const E& element = model.element(built.handle);
    element.add_geometric_stiffness(
        odyn::InputOf<E>{{&ws.frames[built.a.index], &ws.frames[built.b.index]}, ws.t}, lambda,
        analytic);
    for (int k = 0; k < E::num_bodies; ++k) {
      const BodyId body = element.bodies()[k];
      if (body.is_ground()) continue;
      const int offset = Model::configuration_offset(body);
      auto share_at = [&](const Workspace& state) {
        Workspace copy = state;
        evaluate(model, copy);
        return Space::Velocity(blocks_of(copy, built.handle).jacobian[k].transpose() * lambda);
      };
      Space::MassBlock numeric;
      for (int i = 0; i < Space::nv; ++i) {
        Workspace plus = ws, minus = ws;
        const Space::Configuration q = ws.q.segment<Space::nq>(offset);
        Space::integrate(q, eps * Space::Velocity::Unit(i), plus.q.segment<Space::nq>(offset));
        Space::integrate(q, -eps * Space::Velocity::Unit(i), minus.q.segment<Space::nq>(offset));
        numeric.col(i) = (share_at(plus) - share_at(minus)) / (2.0 * eps);
      }
      INFO("geometric stiffness, body side " << k << "\nanalytic:\n"
                                             << analytic[k] << "\nnumeric:\n"
                                             << numeric);
      CHECK(relative_error(analytic[k], numeric) < 1e-6);
      CHECK(numeric.norm() > 1e-2);  // the share turns with the body: a meaningful check
    }
  }
}

// --- Independent geometric residuals at an assembled pose ------------------------------------

struct Pose {
  Vector3d x = Vector3d::Zero();
  Matrix3d r = Matrix3d::Identity();
  Vector3d point(const Vector3d& local) const { return x + r * local; }
  Vector3d axis(const sp::JointFrame& f) const { return (r * f.axis).normalized(); }
  // Reference direction: the given reference made perpendicular to the axis.
  Vector3d reference(const sp::JointFrame& f) const {
    const Vector3d w = f.axis.normalized();
    return (r * (f.reference - f.reference.dot(w) * w)).normalized();
  }
};

Pose pose_of(const Model& model, const Workspace& ws, BodyId body) {
  Pose p;
  if (body.is_ground()) return p;
  const auto q = ws.q.segment<Space::nq>(Model::configuration_offset(body));
  p.x = q.head<3>();
  p.r = Quaterniond(q[3], q[4], q[5], q[6]).normalized().toRotationMatrix();
  (void)model;
  return p;
}

double wrap_angle(double angle) {
  return std::remainder(angle, 2.0 * std::numbers::pi);
}

/// Largest violation of the joint's defining geometry, written from the scene's local frames.
template <class E>
double geometric_residual(const Scene& s, const Pose& a, const Pose& b, double t) {
  const Vector3d pa = a.point(s.on_a.point), pb = b.point(s.on_b.point);
  const Vector3d za = a.axis(s.on_a), zb = b.axis(s.on_b);
  const Vector3d xa = a.reference(s.on_a), xb = b.reference(s.on_b);
  const Vector3d ya = za.cross(xa);
  if constexpr (std::is_same_v<E, sp::Revolute>)
    return std::max((pa - pb).norm(), za.cross(zb).norm());
  if constexpr (std::is_same_v<E, sp::Spherical>) return (pa - pb).norm();
  if constexpr (std::is_same_v<E, sp::Universal>)
    return std::max((pa - pb).norm(), std::abs(za.dot(b.axis(s.on_b_cross))));
  if constexpr (std::is_same_v<E, sp::CvJoint>)  // no twist: u_a . v_b = v_a . u_b
    return std::max((pa - pb).norm(), std::abs(xa.dot(zb.cross(xb)) - ya.dot(xb)));
  if constexpr (std::is_same_v<E, sp::Cylindrical>)
    return std::max(za.cross(zb).norm(), (pb - pa).cross(za).norm());
  if constexpr (std::is_same_v<E, sp::Translational>)
    return std::max({za.cross(zb).norm(), (pb - pa).cross(za).norm(), std::abs(ya.dot(xb))});
  if constexpr (std::is_same_v<E, sp::Fixed>)
    return std::max({(pa - pb).norm(), (za - zb).norm(), (xa - xb).norm()});
  if constexpr (std::is_same_v<E, sp::Distance>)
    return std::abs((b.point(s.on_b_far.point) - pa).norm() - s.length);
  if constexpr (std::is_same_v<E, sp::InLine>) return (pb - pa).cross(za).norm();
  if constexpr (std::is_same_v<E, sp::InPlane>) return std::abs(za.dot(pb - pa));
  if constexpr (std::is_same_v<E, sp::Orientation>)
    return std::max((za - zb).norm(), (xa - xb).norm());
  if constexpr (std::is_same_v<E, sp::ParallelAxes>) return za.cross(zb).norm();
  if constexpr (std::is_same_v<E, sp::Perpendicular>) return std::abs(za.dot(b.axis(s.on_b_cross)));
  if constexpr (std::is_same_v<E, sp::PlanarJoint>)
    return std::max(std::abs(za.dot(pb - pa)), za.cross(zb).norm());
  if constexpr (std::is_same_v<E, sp::RevoluteDriver>)
    return std::abs(wrap_angle(std::atan2(ya.dot(xb), xa.dot(xb)) - harmonic_motion().position(t)));
  if constexpr (std::is_same_v<E, sp::TranslationalDriver>)
    return std::abs(za.dot(pb - pa) - polynomial_motion().position(t));
  return 1.0;
}

template <class E>
void check_assembly(const Scene& s, std::uint32_t seed) {
  // A pose 1 cm / 0.02 rad away from the assembled one.
  Built<E> built = build<E>(s, seed, 0.01, 0.02);
  Workspace ws(built.model);
  ws.t = kTime;
  {
    const double before = geometric_residual<E>(s, pose_of(built.model, ws, built.a),
                                                pose_of(built.model, ws, built.b), ws.t);
    // Drivers start off their motion on purpose (the motion is not zero at kTime).
    // (A one-equation primitive may start closer by chance: 5.8e-5 for the perpendicular one.)
    CHECK(before > 1e-5);
  }
  odyn::assemble(built.model, ws);
  evaluate(built.model, ws);
  CHECK(ws.phi.cwiseAbs().maxCoeff() < 1e-12);
  const double after = geometric_residual<E>(s, pose_of(built.model, ws, built.a),
                                             pose_of(built.model, ws, built.b), ws.t);
  CHECK(after < 1e-11);
  // The assembled velocities satisfy Phi_q v + Phi_t = 0 as well.
  CHECK(constraint_velocity(built.model, ws, built.handle).cwiseAbs().maxCoeff() < 1e-10);
}

template <class E>
void check_constraint_type() {
  for (const bool ground_a : {false, true}) {
    for (const std::uint32_t seed : {11u, 29u}) {
      const Scene scene = make_scene(seed, ground_a);
      SECTION(std::string(ground_a ? "ground as body a" : "two moving bodies") + ", seed " +
              std::to_string(seed)) {
        SECTION("derivatives against finite differences") {
          // A pose well away from the assembled one: 0.2 m and 0.5 rad.
          check_derivatives(build<E>(scene, seed, 0.2, 0.5));
        }
        SECTION("assembly from a perturbed pose") {
          check_assembly<E>(scene, seed);
        }
      }
    }
  }
}

}  // namespace

TEST_CASE("Revolute: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::Revolute>();
}
TEST_CASE("Translational: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::Translational>();
}
TEST_CASE("Spherical: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::Spherical>();
}
TEST_CASE("Universal: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::Universal>();
}
TEST_CASE("CvJoint: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::CvJoint>();
}
TEST_CASE("Cylindrical: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::Cylindrical>();
}
TEST_CASE("Fixed: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::Fixed>();
}
TEST_CASE("Distance: Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::Distance>();
}
TEST_CASE("Joint primitives: Jacobian, Phi_t, gamma and assembly", "[joints][primitives]") {
  SECTION("in line") {
    check_constraint_type<sp::InLine>();
  }
  SECTION("in plane") {
    check_constraint_type<sp::InPlane>();
  }
  SECTION("orientation") {
    check_constraint_type<sp::Orientation>();
  }
  SECTION("parallel axes") {
    check_constraint_type<sp::ParallelAxes>();
  }
  SECTION("perpendicular") {
    check_constraint_type<sp::Perpendicular>();
  }
  SECTION("planar") {
    check_constraint_type<sp::PlanarJoint>();
  }
}
TEST_CASE("RevoluteDriver (harmonic): Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::RevoluteDriver>();
}
TEST_CASE("TranslationalDriver (polynomial): Jacobian, Phi_t, gamma and assembly", "[joints]") {
  check_constraint_type<sp::TranslationalDriver>();
}

TEST_CASE("Drivers assembled together with the joint they drive", "[joints]") {
  const Scene s = make_scene(47u, false);
  SECTION("revolute + revolute driver") {
    Built<sp::Revolute> built = build<sp::Revolute>(s, 47u, 0.01, 0.02);
    built.model.add(
        sp::RevoluteDriver("angle driver", built.model.element(built.handle), harmonic_motion()));
    Workspace ws(built.model);
    ws.t = kTime;
    odyn::assemble(built.model, ws);
    odyn::update_frames(built.model, ws);
    odyn::evaluate_constraints(built.model, ws);
    CHECK(ws.phi.cwiseAbs().maxCoeff() < 1e-12);
    const Pose a = pose_of(built.model, ws, built.a), b = pose_of(built.model, ws, built.b);
    CHECK(geometric_residual<sp::Revolute>(s, a, b, ws.t) < 1e-11);
    CHECK(geometric_residual<sp::RevoluteDriver>(s, a, b, ws.t) < 1e-11);
    // One degree of freedom left, driven: the relative angular velocity about the axis is g'.
    const Vector3d relative = b.r * ws.v.segment<3>(Model::velocity_offset(built.b) + 3) -
                              a.r * ws.v.segment<3>(Model::velocity_offset(built.a) + 3);
    CHECK(relative.dot(a.axis(s.on_a)) == Approx(harmonic_motion().velocity(ws.t)).margin(1e-10));
  }
  SECTION("translational + translational driver") {
    Built<sp::Translational> built = build<sp::Translational>(s, 47u, 0.01, 0.02);
    built.model.add(sp::TranslationalDriver("slide driver", built.model.element(built.handle),
                                            polynomial_motion()));
    Workspace ws(built.model);
    ws.t = kTime;
    odyn::assemble(built.model, ws);
    odyn::update_frames(built.model, ws);
    odyn::evaluate_constraints(built.model, ws);
    CHECK(ws.phi.cwiseAbs().maxCoeff() < 1e-12);
    const Pose a = pose_of(built.model, ws, built.a), b = pose_of(built.model, ws, built.b);
    CHECK(geometric_residual<sp::Translational>(s, a, b, ws.t) < 1e-11);
    CHECK(geometric_residual<sp::TranslationalDriver>(s, a, b, ws.t) < 1e-11);
  }
}

TEST_CASE("quaternion_exp agrees with Eigen's angle-axis rotation at every size", "[rotation]") {
  // Angles below 1e-4 take sin(x)/x by its series, the others sin and cos: both within a few
  // ulps of the reference, and no 0/0 at zero.
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  for (const double angle : {0.0, 1e-12, 1e-6, 0.99e-4, 1e-4, 1.01e-4, 0.05, 0.2, 1.0, 3.0, 7.0}) {
    const Eigen::Quaterniond expected(Eigen::AngleAxisd(angle, axis));
    const Eigen::Quaterniond q = odyn::quaternion_exp(angle * axis);
    CAPTURE(angle);
    CHECK((q.coeffs() - expected.coeffs()).cwiseAbs().maxCoeff() < 4e-16);
    CHECK(std::abs(q.norm() - 1.0) < 4e-16);
  }
}

TEST_CASE("A block on an inclined planar joint slides and spins as the closed form says",
          "[joints][primitives]") {
  // The plane's normal n is z tilted by alpha about x; gravity's part in the plane, g sin(alpha)
  // down the slope, is the block's only acceleration, and its spin about n (a principal axis)
  // stays constant. Absolute and joint coordinates (the planar joint carries the block in a
  // tree) against p(t) = v0 t + g_plane t^2 / 2 and R(t) = R_x(-alpha) R_z(omega t).
  const double alpha = 0.3, g = 9.81, omega = 2.0, t_end = 1.0;
  const Eigen::Vector3d n(0.0, std::sin(alpha), std::cos(alpha));
  const Eigen::Vector3d gravity(0.0, 0.0, -g), v0(1.0, 0.0, 0.0);
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(-alpha, Vector3d::UnitX()));
  for (const char* coordinates : {"absolute", "joint"}) {
    Model model;
    sp::Body block{.name = "block", .mass = 2.0, .inertia = sp::Body::principal(0.1, 0.2, 0.3)};
    block.orientation = tilt;
    block.linear_velocity = v0;
    block.angular_velocity = Vector3d(0.0, 0.0, omega);  // body axes: about n
    const BodyId b = model.add_body(block);
    model.add(sp::PlanarJoint("slope", odyn::ground, sp::JointFrame{Vector3d::Zero(), n}, b,
                              sp::JointFrame{}));
    model.add(sp::Gravity("gravity", gravity));
    Workspace ws(model);
    odyn::DynamicsSettings settings;
    settings.integrator = "dop853";
    settings.coordinates = coordinates;
    settings.rtol = settings.atol = 1e-11;
    settings.t_end = t_end;
    settings.output_interval = t_end;
    const odyn::RunSummary summary = odyn::simulate(model, ws, settings, [](const auto&) {});
    INFO(coordinates);
    CHECK(summary.coordinates == coordinates);
    const Vector3d g_plane = gravity - gravity.dot(n) * n;
    CHECK(std::abs(g_plane.norm() - g * std::sin(alpha)) < 1e-12);
    const Vector3d position = v0 * t_end + 0.5 * g_plane * t_end * t_end;
    const Eigen::Quaterniond orientation =
        tilt * Eigen::Quaterniond(Eigen::AngleAxisd(omega * t_end, Vector3d::UnitZ()));
    const Quaterniond q(ws.q[3], ws.q[4], ws.q[5], ws.q[6]);
    INFO("position " << ws.q.head<3>().transpose() << " vs " << position.transpose());
    CHECK((ws.q.head<3>() - position).norm() < 1e-8);
    CHECK(q.angularDistance(orientation) < 1e-8);
  }
}

TEST_CASE(
    "A bent driveline: a constant-velocity joint turns its output shaft with the input, "
    "a universal joint as tan psi = tan phi / cos beta",
    "[joints]") {
  // Shaft a turns about z at the constant rate omega (a driver on its bearing); shaft b's axis
  // d is z tilted by beta about y (a parallel-axes primitive to the ground), and the joint
  // between them sits where the axes cross. b's pose is R(d, psi) R(y, beta), with psi = phi
  // for the constant-velocity joint and tan psi = tan phi / cos beta for a cross with its arms
  // along x on a and y on b. A load torque T against b's turning needs a motor torque T on a
  // through the constant-velocity joint (equal speeds: the power goes through).
  const double beta = 0.5, omega = 3.0 * std::numbers::pi, load = 2.5, t_end = 1.3;
  const Vector3d z = Vector3d::UnitZ(), d(std::sin(beta), 0.0, std::cos(beta));
  const Eigen::AngleAxisd tilt(beta, Vector3d::UnitY());
  const auto output_angle = [&](bool homokinetic, double phi) {
    return homokinetic ? phi : std::atan2(std::sin(phi), std::cos(phi) * std::cos(beta));
  };
  for (const bool homokinetic : {true, false}) {
    for (const char* coordinates : {"absolute", "joint"}) {
      SECTION(std::string(homokinetic ? "constant-velocity" : "universal") + ", " + coordinates) {
        Model model;
        sp::Body shaft_a{
            .name = "shaft a", .mass = 1.0, .inertia = sp::Body::principal(0.02, 0.02, 0.01)};
        shaft_a.position = Vector3d(0.0, 0.0, -0.5);
        sp::Body shaft_b = shaft_a;
        shaft_b.name = "shaft b";
        shaft_b.position = 0.5 * d;
        shaft_b.orientation = Quaterniond(tilt);
        const BodyId a = model.add_body(shaft_a), b = model.add_body(shaft_b);
        const sp::Revolute bearing("bearing", odyn::ground, {Vector3d(0, 0, -0.5), z}, a, {});
        model.add(bearing);
        model.add(sp::ParallelAxes("guide", odyn::ground, {0.5 * d, d}, b, {}));
        const sp::JointFrame end_a{Vector3d(0, 0, 0.5), z}, end_b{Vector3d(0, 0, -0.5), z};
        if (homokinetic)
          model.add(sp::CvJoint("joint", a, end_a, b, end_b));
        else
          model.add(sp::Universal("joint", a, {end_a.point, Vector3d::UnitX()}, b,
                                  {end_b.point, Vector3d::UnitY()}));
        const auto motor =
            model.add(sp::RevoluteDriver("motor", bearing, odyn::Motion::constant_velocity(omega)));
        model.add(sp::PointTorque("load", b, Vector3d(-load * d)));
        Workspace ws(model);
        odyn::DynamicsSettings settings;
        settings.integrator = "dop853";
        settings.coordinates = coordinates;
        settings.rtol = settings.atol = 1e-11;
        settings.t_end = t_end;
        settings.output_interval = 0.05;
        double angle_error = 0.0, speed_error = 0.0;
        int outputs = 0;
        const odyn::RunSummary summary =
            odyn::simulate(model, ws, settings, [&](const auto& state) {
              const double phi = omega * state.t, psi = output_angle(homokinetic, phi);
              const Matrix3d expected = (Eigen::AngleAxisd(psi, d) * tilt).toRotationMatrix();
              angle_error =
                  std::max(angle_error, (state.frames[b.index].rotation - expected).norm());
              const Vector3d spin =
                  state.frames[b.index].rotation * state.frames[b.index].angular_velocity;
              // psi' = omega cos(beta) / (1 - sin^2(beta) cos^2(phi)) for the cross.
              const double c = std::cos(phi), s = std::sin(beta);
              const double rate =
                  homokinetic ? omega : omega * std::cos(beta) / (1.0 - s * s * c * c);
              speed_error = std::max(speed_error, (spin - rate * d).norm() / omega);
              ++outputs;
            });
        INFO("largest angle error " << angle_error << ", speed error " << speed_error);
        CHECK(summary.coordinates == coordinates);
        CHECK(outputs == 27);
        CHECK(angle_error < 1e-8);
        CHECK(speed_error < 1e-8);
        if (homokinetic) {
          const auto motor_wrench = odyn::reaction(model, ws, motor, odyn::Side::b);
          INFO("motor torque " << motor_wrench.torque.transpose());
          CHECK(motor_wrench.torque.dot(z) == Approx(load).epsilon(1e-8));
          CHECK(odyn::element_output(model, ws, "joint", "bend") == Approx(beta).epsilon(1e-10));
        }
      }
    }
  }
}

TEST_CASE("A constant-velocity joint refuses a start on its wrong branch", "[joints][errors]") {
  Model model;
  const BodyId b = model.add_body(
      sp::Body{.name = "shaft", .mass = 1.0, .inertia = sp::Body::principal(0.1, 0.1, 0.1)});
  SECTION("references twisted by more than a quarter turn") {
    CHECK_THROWS_WITH(
        model.add(sp::CvJoint("cv", odyn::ground,
                              {Vector3d::Zero(), Vector3d::UnitZ(), Vector3d::UnitX()}, b,
                              {Vector3d::Zero(), Vector3d::UnitZ(), Vector3d(-1.0, 0.2, 0.0)})),
        Catch::Contains("cv: the references") && Catch::Contains("twisted by 168.") &&
            Catch::Contains("leave one out"));
  }
  SECTION("shafts pointing in opposite directions") {
    CHECK_THROWS_WITH(
        model.add(sp::CvJoint("cv", odyn::ground, {Vector3d::Zero(), Vector3d::UnitZ()}, b,
                              {Vector3d::Zero(), -Vector3d::UnitZ()})),
        Catch::Contains("opposite directions"));
  }
}

}  // namespace test_joints
