#pragma once
// Independent reference solution of Andrews' squeezing mechanism of shared/specs/andrews.md, in
// the one minimal coordinate beta (the crank angle). It uses no odyn code on purpose: tests
// check the library's absolute-coordinate solution against it.
//
// Method. Given beta, the mechanism is a chain of closed-form pieces: the crank fixes F; the rod
// FE and the triangle (pivot B) form a dyad that places E (two circles meet); from E, the pairs
// rod GE + link AG and rod HE + link AH are dyads to the ground pivot A. Each dyad is solved
// for its two angles and their first and second derivatives with respect to beta by 2x2
// algebra, so every body pose z_i(beta) and its derivatives dz_i/dbeta, d2z_i/dbeta2 are
// exact; there is no Newton iteration and no drift from the constraints. Lagrange's equation in
// beta, with z' = (dz/dbeta) w and w = beta', is
//   m(beta) beta'' + c(beta) w^2 = mom - dV/dbeta,
//   m = sum_i (m_i |dr_i/dbeta|^2 + I_i (dphi_i/dbeta)^2),  c = dm/dbeta / 2
//     = sum_i (m_i dr_i/dbeta . d2r_i/dbeta2 + I_i dphi_i/dbeta d2phi_i/dbeta2),
// with V the spring energy. It is integrated by Gragg-Bulirsch-Stoer extrapolation of the
// explicit midpoint rule (fixed order 16, fixed macro steps). The reduced equation is not
// stiff: the stiff spring acts on a single coordinate whose motion is resolved anyway, so an
// explicit method of high order is the cheapest way to ~1e-13.
//
// The absolute model (bodies, pins, pin forces) is used only for outputs and checks: poses,
// velocities and accelerations of the 7 bodies, and the pin forces from
// M z'' + Phi_z^T lambda = Q (least squares over the 21 body equations, which are consistent).

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace andrews_reference {

// ---------------------------------------------------------------------------------------------
// Data of the spec (SI units). Points in body coordinates are measured from the centre of mass.

struct Vec2 {
  double x, y;
};

inline constexpr int kBodies = 7;
inline constexpr double kMass[kBodies] = {0.04325, 0.00365, 0.02373, 0.00706,
                                          0.07050, 0.00706, 0.05498};
inline constexpr double kInertia[kBodies] = {2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7,
                                             1.169e-5, 5.667e-7, 1.912e-5};

// Ground points.
inline constexpr Vec2 kGroundO{0, 0}, kGroundA{-0.06934, -0.00227}, kGroundB{-0.03635, 0.03273},
    kGroundC{0.014, 0.072};

// Body points, named <point><body>.
inline constexpr Vec2 kO1{-0.00092, 0}, kF1{0.00608, 0};                // crank OF
inline constexpr Vec2 kF2{0.0115, 0}, kE2{-0.0165, 0};                  // rod FE
inline constexpr Vec2 kB3{-0.01043, 0.01874}, kE3{-0.01043, -0.01626},  // triangle
    kD3{0.00957, 0.00074};
inline constexpr Vec2 kG4{0, 0.00579}, kE4{0, -0.01421};                // rod GE
inline constexpr Vec2 kA5{-0.02308, -0.00916}, kG5{0.01692, -0.00916};  // link AG
inline constexpr Vec2 kH6{-0.00579, 0}, kE6{0.01421, 0};                // rod HE
inline constexpr Vec2 kA7{0.00449, 0.01228}, kH7{0.00449, -0.02772};    // link AH

inline constexpr double kSpringStiffness = 4530;      // N/m, between D (body 3) and C (ground)
inline constexpr double kSpringFreeLength = 0.07785;  // m
inline constexpr double kMotorTorque = 0.033;         // N m on the crank, counter-clockwise

// Initial poses (x, y, phi) of the spec, from its 40-digit computation; all velocities are zero.
struct Pose {
  double x, y, phi;
};
inline constexpr std::array<Pose, kBodies> kInitialPoses = {{
    {9.182485980307614359956e-4, -5.674074562905483222436e-5, -0.06171389001427644963589},
    {-4.491433359933072241283e-3, 2.775362557942899402279e-4, -0.06171389001427644963589},
    {-1.874218667031545762186e-2, 2.048510678907393047663e-2, 0.4552798191630703802559},
    {-3.022293983015888742160e-2, 1.207118235666393932334e-2, 0.7100333697097284349001},
    {-5.323682815570413865568e-2, 1.663184796661630721002e-2, 0.4873649795438425502256},
    {-2.854326853678360407221e-2, -1.072225470725228785757e-2, 1.007879054383935307823},
    {-5.926240280179171659320e-2, -1.060069833271284384241e-2, 1.230547444549821192497},
}};
inline constexpr double kBeta0 = kInitialPoses[0].phi;

// Consistency values of the spec at t = 0 (40-digit computation / published test-set values).
inline constexpr double kSpecBetaDdot0 = 14222.4439199541138705911625887;
inline constexpr double kSpecThetaDdot0 = -10666.8329399655854029433719415;
inline constexpr Vec2 kSpecForceJ3At0{98.56687039624108961, -6.122688344255662655};  // N
inline constexpr double kSpecSpringLength0 = 0.05267251611073667595;                 // m
inline constexpr double kSpecSpringEnergy0 = 1.435796399161668750;                   // J

// Published reference solution at t = 0.03 of the Test Set for IVP Solvers (Mazzia, Magherini,
// Univ. of Bari; formerly Lioen & de Swart, CWI), problem "andrews", subroutine SOLN of its
// Fortran problem file / drivers: y1..y7 (angles beta .. epsilon) and y8..y14 (their rates).
// The spec rates it reliable to ~10 digits in the angles and ~7 in the rates; this header's
// solution agrees with it to 9.6 .. 12.5 digits in the angles and 7.3 .. 10 in the rates.
inline constexpr double kPublishedTestSetTime = 0.03;
inline constexpr std::array<double, 7> kPublishedTestSetAngles = {
    0.1581077119629904e+2, -0.1575637105984298e+2, 0.4082224013073101e-1, -0.5347301163226948e+0,
    0.5244099658805304e+0, 0.5347301163226948e+0,  0.1048080741042263e+1};
inline constexpr std::array<double, 7> kPublishedTestSetRates = {
    0.1139920302151208e+4, -0.1424379294994111e+4, 0.1103291221937134e+2, 0.1929337464421385e+2,
    0.5735699284790808e+0, -0.1929337464421385e+2, 0.3231791658026955e+0};

// ---------------------------------------------------------------------------------------------
// Test-set coordinates.

// The seven test-set angles in the order beta, Theta, gamma, Phi, delta, Omega, epsilon, their
// rates, at time t. Angles are continuous in time (beta and Theta are not reduced mod 2 pi).
struct State {
  double t;
  std::array<double, 7> angle;
  std::array<double, 7> rate;
};

// Test-set angles from body angles: beta = phi1, Theta = phi2 - phi1, gamma = phi3,
// Phi = phi4 - phi5, delta = phi5, Omega = phi6 - phi7, epsilon = phi7. Linear, so the same map
// takes body rates and accelerations to angle rates and accelerations.
inline std::array<double, 7> test_set_angles(const std::array<double, kBodies>& phi) {
  return {phi[0], phi[1] - phi[0], phi[2], phi[3] - phi[4], phi[4], phi[5] - phi[6], phi[6]};
}

// ---------------------------------------------------------------------------------------------
// Kinematics in beta.

namespace detail {

inline Vec2 operator+(Vec2 a, Vec2 b) {
  return {a.x + b.x, a.y + b.y};
}
inline Vec2 operator-(Vec2 a, Vec2 b) {
  return {a.x - b.x, a.y - b.y};
}
inline Vec2 operator*(double s, Vec2 a) {
  return {s * a.x, s * a.y};
}
inline double dot(Vec2 a, Vec2 b) {
  return a.x * b.x + a.y * b.y;
}
inline double cross(Vec2 a, Vec2 b) {
  return a.x * b.y - a.y * b.x;
}
// Rotation by +90 degrees.
inline Vec2 perp(Vec2 a) {
  return {-a.y, a.x};
}
inline Vec2 rotate(double c, double s, Vec2 a) {
  return {c * a.x - s * a.y, s * a.x + c * a.y};
}

// A point and its first and second derivatives with respect to beta.
struct PointMotion {
  Vec2 p, dp, ddp;
};

}  // namespace detail

// A body's pose and its first and second derivatives with respect to beta. With w = beta' and
// a = beta'', the body's velocity is d * w and its acceleration d * a + dd * w^2.
struct BodyMotion {
  double phi, dphi, ddphi;
  Vec2 r, dr, ddr;  // centre of mass
  double cos_phi, sin_phi;
};

namespace detail {

// Where body point s is, given the body's motion.
inline PointMotion point_of(const BodyMotion& b, Vec2 s) {
  const Vec2 rs = rotate(b.cos_phi, b.sin_phi, s);
  return {b.r + rs, b.dr + b.dphi * perp(rs), b.ddr + b.ddphi * perp(rs) - (b.dphi * b.dphi) * rs};
}

// Body motion from its angle motion and the motion of one of its points s (the inverse of
// point_of).
inline BodyMotion body_at(double phi, double dphi, double ddphi, const PointMotion& at, Vec2 s) {
  BodyMotion b;
  b.phi = phi;
  b.dphi = dphi;
  b.ddphi = ddphi;
  b.cos_phi = std::cos(phi);
  b.sin_phi = std::sin(phi);
  const Vec2 rs = rotate(b.cos_phi, b.sin_phi, s);
  b.r = at.p - rs;
  b.dr = at.dp - dphi * perp(rs);
  b.ddr = at.ddp - ddphi * perp(rs) + (dphi * dphi) * rs;
  return b;
}

// The angle of vector v minus that of the body vector v0, taken within pi of phi_near. The
// bodies 2..7 only swing (their angles stay within a fraction of pi of the initial ones), so
// this keeps them continuous without any history.
inline double angle_near(Vec2 v, Vec2 v0, double phi_near) {
  const double raw = std::atan2(v.y, v.x) - std::atan2(v0.y, v0.x);
  return phi_near + std::remainder(raw - phi_near, 2 * std::numbers::pi);
}

struct DyadMotion {
  double a, da, dda;  // angle of body a (the one through the moving point P)
  double b, db, ddb;  // angle of body b (the one through the ground point Q)
  double cross_uv;    // u x v: zero at a dead point of the dyad
};

// Dyad: body a carries the moving point P and the joint X at u = R(a) u0 from P; body b turns
// about the ground point Q and carries X at v = R(b) v0 from Q. Closure: P + u = Q + v.
// side = +1 or -1 picks the assembly: the sign of (Q - P) x (X - P).
inline DyadMotion solve_dyad(const PointMotion& P, Vec2 Q, Vec2 u0, Vec2 v0, double side,
                             double a_near, double b_near) {
  const Vec2 d = Q - P.p;
  const double dist2 = dot(d, d), dist = std::sqrt(dist2);
  const double lu2 = dot(u0, u0), lv2 = dot(v0, v0);
  const double along = (lu2 - lv2 + dist2) / (2 * dist);
  const double h2 = lu2 - along * along;
  if (!(h2 > 0)) throw std::runtime_error("andrews_reference: a dyad cannot close");
  const double height = side * std::sqrt(h2);
  const Vec2 u = (along / dist) * d + (height / dist) * perp(d);  // X - P
  const Vec2 v = u - d;                                           // X - Q
  DyadMotion m;
  m.a = angle_near(u, u0, a_near);
  m.b = angle_near(v, v0, b_near);
  m.cross_uv = cross(u, v);
  // d/dbeta of the closure: dP + da perp(u) = db perp(v). Dot with v and with u.
  m.da = -dot(P.dp, v) / m.cross_uv;
  m.db = -dot(P.dp, u) / m.cross_uv;
  // Second derivative: ddP + dda perp(u) - da^2 u = ddb perp(v) - db^2 v.
  const Vec2 w = P.ddp - (m.da * m.da) * u + (m.db * m.db) * v;
  m.dda = -dot(w, v) / m.cross_uv;
  m.ddb = -dot(w, u) / m.cross_uv;
  return m;
}

// Assembly branches, read off the spec's initial poses (with them, kinematics(kBeta0)
// reproduces all of kInitialPoses to 1e-15).
inline constexpr double kSideFEB = 1, kSideEGA = -1, kSideEHA = 1;

}  // namespace detail

struct Kinematics {
  std::array<BodyMotion, kBodies> body;
  double min_abs_cross;  // smallest |u x v| of the three dyads, m^2 (distance from a dead point)
};

// All body motions at crank angle beta (derivatives with respect to beta).
inline Kinematics kinematics(double beta) {
  using namespace detail;
  Kinematics k;
  auto& b = k.body;
  const PointMotion O{kGroundO, {0, 0}, {0, 0}};
  b[0] = body_at(beta, 1, 0, O, kO1);
  const PointMotion F = point_of(b[0], kF1);

  const DyadMotion feb = solve_dyad(F, kGroundB, kE2 - kF2, kE3 - kB3, kSideFEB,
                                    kInitialPoses[1].phi, kInitialPoses[2].phi);
  b[1] = body_at(feb.a, feb.da, feb.dda, F, kF2);
  b[2] = body_at(feb.b, feb.db, feb.ddb, {kGroundB, {0, 0}, {0, 0}}, kB3);
  const PointMotion E = point_of(b[1], kE2);

  const DyadMotion ega = solve_dyad(E, kGroundA, kG4 - kE4, kG5 - kA5, kSideEGA,
                                    kInitialPoses[3].phi, kInitialPoses[4].phi);
  b[3] = body_at(ega.a, ega.da, ega.dda, E, kE4);
  b[4] = body_at(ega.b, ega.db, ega.ddb, {kGroundA, {0, 0}, {0, 0}}, kA5);

  const DyadMotion eha = solve_dyad(E, kGroundA, kH6 - kE6, kH7 - kA7, kSideEHA,
                                    kInitialPoses[5].phi, kInitialPoses[6].phi);
  b[5] = body_at(eha.a, eha.da, eha.dda, E, kE6);
  b[6] = body_at(eha.b, eha.db, eha.ddb, {kGroundA, {0, 0}, {0, 0}}, kA7);

  k.min_abs_cross =
      std::min({std::abs(feb.cross_uv), std::abs(ega.cross_uv), std::abs(eha.cross_uv)});
  return k;
}

// ---------------------------------------------------------------------------------------------
// Spring and reduced dynamics.

struct Spring {
  double length;    // L = |r_D - r_C|
  double energy;    // k (L - l0)^2 / 2
  Vec2 force_on_D;  // -k (L - l0) (r_D - r_C) / L
  double dV_dbeta;  // generalized spring force is -dV/dbeta
};

inline Spring spring(const Kinematics& k) {
  using namespace detail;
  const PointMotion D = point_of(k.body[2], kD3);
  const Vec2 cd = D.p - kGroundC;
  Spring s;
  s.length = std::sqrt(dot(cd, cd));
  const double stretch = s.length - kSpringFreeLength;
  s.energy = 0.5 * kSpringStiffness * stretch * stretch;
  s.force_on_D = (-kSpringStiffness * stretch / s.length) * cd;
  s.dV_dbeta = -dot(s.force_on_D, D.dp);
  return s;
}

struct Reduced {
  double mass;      // m(beta) = sum m_i |dr_i|^2 + I_i dphi_i^2, kg m^2
  double coriolis;  // c(beta) = dm/dbeta / 2
  double force;     // mom - dV/dbeta, N m
};

inline Reduced reduced(const Kinematics& k) {
  using detail::dot;
  Reduced red{0, 0, 0};
  for (int i = 0; i < kBodies; ++i) {
    const BodyMotion& b = k.body[i];
    red.mass += kMass[i] * dot(b.dr, b.dr) + kInertia[i] * b.dphi * b.dphi;
    red.coriolis += kMass[i] * dot(b.dr, b.ddr) + kInertia[i] * b.dphi * b.ddphi;
  }
  red.force = kMotorTorque - spring(k).dV_dbeta;
  return red;
}

// beta'' at crank angle beta and crank rate w.
inline double crank_acceleration(double beta, double w) {
  const Reduced r = reduced(kinematics(beta));
  return (r.force - r.coriolis * w * w) / r.mass;
}

// ---------------------------------------------------------------------------------------------
// Outputs at a state (beta, w) of the reduced system.

inline State make_state(double t, double beta, double w) {
  const Kinematics k = kinematics(beta);
  std::array<double, kBodies> phi, dphi;
  for (int i = 0; i < kBodies; ++i) {
    phi[i] = k.body[i].phi;
    dphi[i] = k.body[i].dphi * w;
  }
  return {t, test_set_angles(phi), test_set_angles(dphi)};
}

// Accelerations of the seven test-set angles at a state.
inline std::array<double, 7> angle_accelerations(const State& s) {
  const double beta = s.angle[0], w = s.rate[0];
  const Kinematics k = kinematics(beta);
  const Reduced r = reduced(k);
  const double a = (r.force - r.coriolis * w * w) / r.mass;
  std::array<double, kBodies> ddphi;
  for (int i = 0; i < kBodies; ++i) ddphi[i] = k.body[i].dphi * a + k.body[i].ddphi * w * w;
  return test_set_angles(ddphi);
}

// Absolute state of one body: pose, velocity and acceleration of the centre of mass and angle.
struct BodyState {
  double x, y, phi;
  double vx, vy, omega;
  double ax, ay, alpha;
};

inline std::array<BodyState, kBodies> body_states(const State& s) {
  const double beta = s.angle[0], w = s.rate[0];
  const Kinematics k = kinematics(beta);
  const Reduced r = reduced(k);
  const double a = (r.force - r.coriolis * w * w) / r.mass;
  std::array<BodyState, kBodies> out;
  for (int i = 0; i < kBodies; ++i) {
    const BodyMotion& b = k.body[i];
    out[i] = {b.r.x,
              b.r.y,
              b.phi,
              b.dr.x * w,
              b.dr.y * w,
              b.dphi * w,
              b.dr.x * a + b.ddr.x * w * w,
              b.dr.y * a + b.ddr.y * w * w,
              b.dphi * a + b.ddphi * w * w};
  }
  return out;
}

inline std::array<Pose, kBodies> poses(const State& s) {
  const auto b = body_states(s);
  std::array<Pose, kBodies> out;
  for (int i = 0; i < kBodies; ++i) out[i] = {b[i].x, b[i].y, b[i].phi};
  return out;
}

struct Energy {
  double kinetic, potential, motor_work;  // potential: spring; motor_work = mom (phi1 - phi1(0))
  // Conserved: kinetic + potential - motor_work = spring energy at t = 0 (kSpecSpringEnergy0).
  double balance() const { return kinetic + potential - motor_work; }
};

inline Energy energy(const State& s) {
  const double beta = s.angle[0], w = s.rate[0];
  const Kinematics k = kinematics(beta);
  return {0.5 * reduced(k).mass * w * w, spring(k).energy, kMotorTorque * (beta - kBeta0)};
}

// ---------------------------------------------------------------------------------------------
// Pin forces.

// A pin: point s_a of body a on point s_b of body b; body -1 is the ground (s_b then is the
// ground point). Residual r_a + R(phi_a) s_a - r_b - R(phi_b) s_b.
struct Pin {
  int a;
  Vec2 s_a;
  int b;
  Vec2 s_b;
};

inline constexpr std::array<Pin, 10> kPins = {{
    {0, kO1, -1, kGroundO},  // J1 crank . O - ground
    {0, kF1, 1, kF2},        // J2 crank . F - rod FE . F
    {1, kE2, 2, kE3},        // J3 rod FE . E - triangle . E
    {2, kB3, -1, kGroundB},  // J4 triangle . B - ground
    {1, kE2, 3, kE4},        // J5 rod FE . E - rod GE . E
    {3, kG4, 4, kG5},        // J6 rod GE . G - link AG . G
    {4, kA5, -1, kGroundA},  // J7 link AG . A - ground
    {1, kE2, 5, kE6},        // J8 rod FE . E - rod HE . E
    {5, kH6, 6, kH7},        // J9 rod HE . H - link AH . H
    {6, kA7, -1, kGroundA},  // J10 link AH . A - ground
}};

// lambda_j of M z'' + Phi_z^T lambda = Q: the force that body a of pin j exerts on body b, N.
// Solved by least squares over the 21 body equations; they are consistent (z'' is the true
// acceleration), so the residual is rounding only.
inline std::array<Eigen::Vector2d, 10> pin_forces(const State& s) {
  using namespace detail;
  const auto bodies = body_states(s);
  const Kinematics k = kinematics(s.angle[0]);
  Eigen::Matrix<double, 21, 20> phi_z_t = Eigen::Matrix<double, 21, 20>::Zero();
  for (int j = 0; j < 10; ++j) {
    const Pin& pin = kPins[j];
    auto add = [&](int body, Vec2 s_body, double sign) {
      if (body < 0) return;
      const Vec2 rs = rotate(k.body[body].cos_phi, k.body[body].sin_phi, s_body);
      phi_z_t(3 * body, 2 * j) += sign;
      phi_z_t(3 * body + 1, 2 * j + 1) += sign;
      phi_z_t(3 * body + 2, 2 * j) += sign * -rs.y;  // d(R s)/dphi = perp(R s)
      phi_z_t(3 * body + 2, 2 * j + 1) += sign * rs.x;
    };
    add(pin.a, pin.s_a, 1);
    add(pin.b, pin.s_b, -1);
  }
  Eigen::Matrix<double, 21, 1> rhs;  // Q - M z''
  for (int i = 0; i < kBodies; ++i) {
    rhs(3 * i) = -kMass[i] * bodies[i].ax;
    rhs(3 * i + 1) = -kMass[i] * bodies[i].ay;
    rhs(3 * i + 2) = -kInertia[i] * bodies[i].alpha;
  }
  rhs(2) += kMotorTorque;
  const Spring sp = spring(k);
  const Vec2 arm = rotate(k.body[2].cos_phi, k.body[2].sin_phi, kD3);
  rhs(6) += sp.force_on_D.x;
  rhs(7) += sp.force_on_D.y;
  rhs(8) += cross(arm, sp.force_on_D);
  const Eigen::Matrix<double, 20, 1> lambda = phi_z_t.colPivHouseholderQr().solve(rhs);
  std::array<Eigen::Vector2d, 10> out;
  for (int j = 0; j < 10; ++j) out[j] = {lambda(2 * j), lambda(2 * j + 1)};
  return out;
}

// ---------------------------------------------------------------------------------------------
// Convenience values at t = 0 (v = 0), for the spec's consistency checks. The accelerations of
// gamma .. epsilon are zero in exact arithmetic; here they come out ~1e-12 (rounding of terms of
// size 1e4), so compare them with an absolute tolerance.

inline State initial_state() {
  return make_state(0, kBeta0, 0);
}

inline double initial_beta_ddot() {
  return angle_accelerations(initial_state())[0];
}
inline double initial_theta_ddot() {
  return angle_accelerations(initial_state())[1];
}
inline Eigen::Vector2d initial_force_j3() {
  return pin_forces(initial_state())[2];
}

// ---------------------------------------------------------------------------------------------
// Integration.

namespace detail {

struct Crank {
  double beta, w;
};

// Step numbers of the extrapolation: all even, so that Gragg's midpoint result has an error
// expansion in even powers of the substep; 8 columns give order 16.
inline constexpr int kColumns = 8;
inline constexpr int kSubsteps[kColumns] = {2, 4, 6, 8, 10, 12, 14, 16};

// One GBS macro step of length H from y, returned as an increment (formed from increments, so
// that beta ~ 16 rad does not cost digits in the extrapolation).
inline Crank gbs_increment(const Crank& y, double H) {
  const double a0 = crank_acceleration(y.beta, y.w);
  Crank table[kColumns];  // Neville tableau, one row kept per column
  for (int j = 0; j < kColumns; ++j) {
    const int n = kSubsteps[j];
    const double h = H / n;
    // Explicit midpoint rule on increments: z_{k+1} = z_{k-1} + 2 h f(y + z_k).
    Crank prev{0, 0}, cur{h * y.w, h * a0};
    for (int i = 1; i < n; ++i) {
      const double beta = y.beta + cur.beta, w = y.w + cur.w;
      const Crank next{prev.beta + 2 * h * w, prev.w + 2 * h * crank_acceleration(beta, w)};
      prev = cur;
      cur = next;
    }
    // Aitken-Neville in h^2: table[m] holds T_{j,m+1}.
    Crank t = cur;
    for (int m = 1; m <= j; ++m) {
      const double ratio = static_cast<double>(n) / kSubsteps[j - m];
      const double factor = 1 / (ratio * ratio - 1);
      const Crank improved{t.beta + (t.beta - table[m - 1].beta) * factor,
                           t.w + (t.w - table[m - 1].w) * factor};
      table[m - 1] = t;
      t = improved;
    }
    table[j] = t;
  }
  return table[kColumns - 1];
}

// Kahan summation: hundreds of steps added to beta ~ 16 would otherwise lose ~1e-13.
inline void add_compensated(double& sum, double& carry, double x) {
  const double y = x - carry, s = sum + y;
  carry = (s - sum) - y;
  sum = s;
}

}  // namespace detail

// Default macro step, s. At 2e-4 (150 steps to t = 0.03, ~10^4 evaluations of the reduced
// equation, a few ms) the angles at t = 0.03 agree with runs at 1/2, 1/4 and 1/8 of the step to
// <= 3e-14 relative (rounding level) and the rates to ~3e-12; at 4e-4 the error is ~2e-12, at
// 1e-3 ~1e-6. The energy balance holds to ~1e-14 relative.
inline constexpr double kDefaultStep = 2e-4;

// Integrates from the spec's initial state (t = 0, all velocities zero) and returns the state
// at each of output_times (non-decreasing, >= 0). Macro steps are at most h and end exactly on
// every output time.
inline std::vector<State> solve(const std::vector<double>& output_times, double h = kDefaultStep) {
  if (!(h > 0)) throw std::invalid_argument("andrews_reference: step must be positive");
  detail::Crank y{kBeta0, 0}, carry{0, 0};
  double t = 0;
  std::vector<State> out;
  out.reserve(output_times.size());
  for (const double t_out : output_times) {
    if (!(t_out >= t)) throw std::invalid_argument("andrews_reference: times must not decrease");
    const double span = t_out - t;
    const long long steps = static_cast<long long>(std::ceil(span / h - 1e-9));
    for (long long i = 0; i < steps; ++i) {
      const detail::Crank d = detail::gbs_increment(y, span / static_cast<double>(steps));
      detail::add_compensated(y.beta, carry.beta, d.beta);
      detail::add_compensated(y.w, carry.w, d.w);
    }
    t = t_out;
    out.push_back(make_state(t, y.beta, y.w));
  }
  return out;
}

inline State solve(double t_end, double h = kDefaultStep) {
  return solve(std::vector<double>{t_end}, h).front();
}

}  // namespace andrews_reference
