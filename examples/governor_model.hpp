#pragma once
// A stiff spring-loaded centrifugal governor (spatial, absolute coordinates), z up, gravity -z.
// A spindle turns about z at a prescribed speed Omega(t) that ramps smoothly from omega0 to
// omega1 over ramp_time. Two arms (i = +1, -1) hang from hinges at P_i = (i a, 0, 0) in the
// spindle frame, hinge axes along the spindle's y; arm i points along
//   d_i = (i sin phi, 0, -cos phi),  phi = angle from the downward vertical.
// A massless link (a distance constraint) of length L joins each arm's point B_i = P_i + b d_i to
// the point S_i = (i e, 0, z_s) of a sleeve that slides along the spindle (turning with it), so
// the sleeve hangs at z_s = -b cos phi - sqrt(L^2 - (a + b sin phi - e)^2) and rises as the arms
// fly out. A spring-damper on the axis pulls the sleeve down towards the spindle point
// (0, 0, z0). 4 bodies (24 velocities), 23 independent equations: one degree of freedom, phi.
//
// Why stiff: the damper is so strong that phi's motion is strongly overdamped. Linearized about
// the equilibrium, M phi'' + C phi' + K phi = 0 with M ~ 0.16 kg m^2, C = c (dz_s/dphi)^2 and
// K ~ k (dz_s/dphi)^2: one fast mode, lambda ~ -C / M ~ -1.4e4 .. -2e4 1/s (the arm rate
// settling onto the slow motion), and one slow, lambda ~ -K / C ~ -5.3 .. -6 1/s (phi creeping to
// the equilibrium that the speed ramp moves from 30 to 40 degrees), 2500 to 3300 times slower.
// Started a few degrees off equilibrium with the arm at rest relative to the spindle, the run has
// a short fast transient and then slow quasi-static tracking: explicit methods are held by
// stability to steps near 1e-4 s throughout. (In absolute coordinates the bodies' positions also
// turn at Omega, 100 to 200 rad/s, which bounds any integrator's steps for accuracy there; in
// joint coordinates only phi's slow motion does.)
//
// tests/reference/governor_reference.hpp integrates the same motion in phi alone; its
// Parameters must stay equal to these (same names and defaults).

#include <array>
#include <cmath>
#include <numbers>

#include <odyn/odyn.hpp>

namespace governor {

namespace sp = odyn::spatial;
using Eigen::Vector3d;

struct Parameters {
  double a = 0.05;  // m, hinge offset from the axis
  double b = 0.15;  // m, hinge to the link's point B on the arm
  double e = 0.03;  // m, axis to the link's point S on the sleeve
  double L = 0.20;  // m, link length

  double arm_mass = 1.0;         // kg, each arm
  double arm_centre = 0.25;      // m, l_c: hinge to the arm's centre of mass, along d
  double arm_transverse = 0.01;  // kg m^2, J: about the centre, across d
  double arm_axial = 1e-4;       // kg m^2, I_a: about d

  // The sleeve's and spindle's inertias do not affect phi (both turn at the driven speed).
  double sleeve_mass = 0.5;          // kg
  double sleeve_axial = 5e-4;        // kg m^2, about z
  double sleeve_transverse = 5e-4;   // kg m^2
  double spindle_mass = 2.0;         // kg
  double spindle_axial = 2e-3;       // kg m^2, about z
  double spindle_transverse = 2e-2;  // kg m^2

  double stiffness = 5e5;  // k, N/m
  double damping = 1e5;    // c, N s/m: |fast| ~ c (dz_s/dphi)^2 / M >= 1e4 needs c ~ 1e5
  double z0 = -0.45;       // m, spindle point on the axis where the spring is anchored

  /// Equilibrium angle at omega0; fixes the spring's free length (see free_length).
  double design_angle = 30.0 * std::numbers::pi / 180.0;   // rad
  double initial_angle = 27.0 * std::numbers::pi / 180.0;  // rad, phi at t = 0 (phi' = 0)
  double omega0 = 100.0;                                   // rad/s, spindle speed for t <= 0
  double omega1 = 200.0;                                   // rad/s, for t >= ramp_time
  double ramp_time = 1.0;                                  // s, T
  double g = 9.81;                                         // m/s^2, along -z
};

/// Spindle speed Omega(t) = omega0 + (omega1 - omega0) (1 - cos(pi t / T)) / 2 on [0, T]: its
/// rate is continuous (zero at both ends), so the driver's acceleration is too.
inline double spindle_speed(double t, const Parameters& p) {
  if (t <= 0.0) return p.omega0;
  if (t >= p.ramp_time) return p.omega1;
  return p.omega0 +
         0.5 * (p.omega1 - p.omega0) * (1.0 - std::cos(std::numbers::pi * t / p.ramp_time));
}
/// Its integral from 0 (the driven angle, zero at the initial pose) and its derivative.
inline double spindle_angle(double t, const Parameters& p) {
  const double T = p.ramp_time, rise = p.omega1 - p.omega0;
  if (t <= 0.0) return p.omega0 * t;
  if (t >= T) return p.omega0 * T + 0.5 * rise * T + p.omega1 * (t - T);
  const double w = std::numbers::pi / T;
  return p.omega0 * t + 0.5 * rise * (t - std::sin(w * t) / w);
}
inline double spindle_acceleration(double t, const Parameters& p) {
  if (t <= 0.0 || t >= p.ramp_time) return 0.0;
  const double w = std::numbers::pi / p.ramp_time;
  return 0.5 * (p.omega1 - p.omega0) * w * std::sin(w * t);
}

/// Sleeve height z_s(phi) and dz_s/dphi, from |B_i - S_i| = L (the sleeve below B_i).
struct SleeveHeight {
  double z, slope;
};
inline SleeveHeight sleeve_height(const Parameters& p, double phi) {
  const double s = std::sin(phi), c = std::cos(phi);
  const double across = p.a + p.b * s - p.e;  // horizontal span of a link
  const double down = std::sqrt(p.L * p.L - across * across);
  return {-p.b * c - down, p.b * s + across * p.b * c / down};
}

/// The spring's free length that makes design_angle the equilibrium at omega0: the spring's
/// moment k (z_s - z0 - free) dz_s/dphi balances the arms' centrifugal moment less gravity's.
inline double free_length(const Parameters& p) {
  const double phi = p.design_angle, s = std::sin(phi), c = std::cos(phi);
  const SleeveHeight h = sleeve_height(p, phi);
  const double m = p.arm_mass, lc = p.arm_centre;
  const double centrifugal =
      p.omega0 * p.omega0 *
      (2.0 * m * (p.a + lc * s) * lc * c + 2.0 * (p.arm_transverse - p.arm_axial) * s * c);
  const double gravity = 2.0 * m * p.g * lc * s + p.sleeve_mass * p.g * h.slope;
  return h.z - p.z0 - (centrifugal - gravity) / (p.stiffness * h.slope);
}

using Model = sp::Model<sp::Revolute, sp::RevoluteDriver, sp::Translational, sp::Distance, sp::Tsda,
                        sp::Gravity>;

struct Governor {
  Model model;
  Parameters parameters;
  double free_length = 0.0;  // m, of the spring
  odyn::BodyId spindle, sleeve;
  std::array<odyn::BodyId, 2> arms;  // i = +1 (x > 0 at t = 0), i = -1
  odyn::Handle<sp::Revolute> bearing;
  odyn::Handle<sp::RevoluteDriver> drive;
  std::array<odyn::Handle<sp::Revolute>, 2> hinges;
  odyn::Handle<sp::Translational> guide;
  std::array<odyn::Handle<sp::Distance>, 2> links;
  odyn::Handle<sp::Tsda> spring;
};

/// Arm direction d_i in the spindle frame.
inline Vector3d arm_direction(double side, double phi) {
  return {side * std::sin(phi), 0.0, -std::cos(phi)};
}

/// Builds the governor at t = 0: spindle angle zero (its frame is the global one), phi =
/// initial_angle, everything turning rigidly with the spindle at omega0 (phi' = 0). Every body
/// starts at the identity orientation, so body axes are global axes at t = 0.
inline Governor build(const Parameters& p = {}) {
  Governor g;
  g.parameters = p;
  g.free_length = free_length(p);
  const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
  const Vector3d spin = p.omega0 * z;  // angular velocity of every body, global = body frame
  const double phi = p.initial_angle;
  const double z_s = sleeve_height(p, phi).z;

  g.spindle = g.model.add_body(
      {.name = "spindle",
       .mass = p.spindle_mass,
       .inertia = sp::Body::principal(p.spindle_transverse, p.spindle_transverse, p.spindle_axial),
       .angular_velocity = spin});
  const std::array<double, 2> sides = {1.0, -1.0};
  std::array<Vector3d, 2> centres;
  for (int k = 0; k < 2; ++k) {
    const Vector3d d = arm_direction(sides[k], phi);
    centres[k] = sides[k] * p.a * x + p.arm_centre * d;
    // Axisymmetric about d: I_a along d, J across.
    const Eigen::Matrix3d inertia =
        p.arm_transverse * (Eigen::Matrix3d::Identity() - d * d.transpose()) +
        p.arm_axial * d * d.transpose();
    g.arms[k] = g.model.add_body({.name = k == 0 ? "arm +" : "arm -",
                                  .mass = p.arm_mass,
                                  .inertia = inertia,
                                  .position = centres[k],
                                  .linear_velocity = spin.cross(centres[k]),
                                  .angular_velocity = spin});
  }
  g.sleeve = g.model.add_body(
      {.name = "sleeve",
       .mass = p.sleeve_mass,
       .inertia = sp::Body::principal(p.sleeve_transverse, p.sleeve_transverse, p.sleeve_axial),
       .position = z_s * z,
       .angular_velocity = spin});

  const sp::Revolute bearing("bearing", odyn::ground, {Vector3d::Zero(), z}, g.spindle,
                             {Vector3d::Zero(), z});
  g.bearing = g.model.add(bearing);
  // The spindle angle follows the ramp's integral; Motion takes any g, g', g''.
  g.drive = g.model.add(
      sp::RevoluteDriver("drive", bearing,
                         odyn::Motion{[p](double t) { return spindle_angle(t, p); },
                                      [p](double t) { return spindle_speed(t, p); },
                                      [p](double t) { return spindle_acceleration(t, p); }}));
  for (int k = 0; k < 2; ++k) {
    const Vector3d pivot = sides[k] * p.a * x;
    const Vector3d d = arm_direction(sides[k], phi);
    g.hinges[k] = g.model.add(sp::Revolute(k == 0 ? "hinge +" : "hinge -", g.spindle, {pivot, y},
                                           g.arms[k], {pivot - centres[k], y}));
    g.links[k] =
        g.model.add(sp::Distance(k == 0 ? "link +" : "link -", g.arms[k], (p.b - p.arm_centre) * d,
                                 g.sleeve, sides[k] * p.e * x, p.L));
  }
  g.guide = g.model.add(
      sp::Translational("sleeve guide", g.spindle, {z_s * z, z}, g.sleeve, {Vector3d::Zero(), z}));
  g.spring = g.model.add(
      sp::Tsda("spring", g.spindle, p.z0 * z, g.sleeve, Vector3d::Zero(),
               {.stiffness = p.stiffness, .damping = p.damping, .free_length = g.free_length}));
  g.model.add(sp::Gravity("gravity", {0.0, 0.0, -p.g}));
  return g;
}

/// phi of arm `k` (0: i = +1, 1: i = -1), from its direction in the spindle frame.
inline double arm_angle(const Governor& g, const odyn::Workspace<Model>& ws, int k = 0) {
  const double side = k == 0 ? 1.0 : -1.0;
  const auto& spindle = ws.frames[g.spindle.index];
  const auto& arm = ws.frames[g.arms[k].index];
  // Body axes were global at t = 0, so d_i at the initial angle is the arm's body direction.
  const Vector3d d =
      spindle.rotation.transpose() * arm.direction(arm_direction(side, g.parameters.initial_angle));
  return std::atan2(side * d.x(), -d.z());
}

}  // namespace governor
