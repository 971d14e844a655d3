#pragma once
// A spatial test model shared by the statics and modes tests: a plate on a ball joint held by
// three springs, whose equilibrium an energy minimization gives independently.

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <array>
#include <string>

#include <odyn/odyn.hpp>

namespace spring_plate {

/// The element types of the statics and modes tests' spatial models (one instantiation).
using Model = odyn::spatial::Model<odyn::spatial::Revolute, odyn::spatial::Universal,
                                   odyn::spatial::Spherical, odyn::spatial::Rsda,
                                   odyn::spatial::Tsda, odyn::spatial::Gravity>;

/// A 2 kg plate hung from a ball joint and held by three springs to the ground, under gravity.
/// Its equilibrium is the minimum of its potential energy over its orientation (minimum(), in
/// Z-Y-X Euler angles).
struct SpringPlate {
  static constexpr double mass = 2.0, g = 9.81;
  const Eigen::Vector3d ball{0.0, 0.0, 0.3};  // the joint's point on the plate
  const std::array<Eigen::Vector3d, 3> on_plate{Eigen::Vector3d(0.4, 0.0, -0.1),
                                                Eigen::Vector3d(-0.2, 0.35, -0.1),
                                                Eigen::Vector3d(-0.2, -0.35, 0.1)};
  const std::array<Eigen::Vector3d, 3> anchors{Eigen::Vector3d(1.0, 0.2, -0.5),
                                               Eigen::Vector3d(-0.6, 1.0, 0.2),
                                               Eigen::Vector3d(-0.5, -0.9, -0.8)};
  const std::array<double, 3> stiffness{40.0, 60.0, 50.0}, free_length{0.5, 0.6, 0.4};

  static Eigen::Matrix3d rotation(const Eigen::Vector3d& zyx) {
    return (Eigen::AngleAxisd(zyx[0], Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(zyx[1], Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(zyx[2], Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
  double energy(const Eigen::Vector3d& zyx) const {
    const Eigen::Matrix3d r = rotation(zyx);
    const Eigen::Vector3d centre = -r * ball;
    double v = mass * g * centre.z();
    for (std::size_t i = 0; i < 3; ++i) {
      const double stretch = (centre + r * on_plate[i] - anchors[i]).norm() - free_length[i];
      v += 0.5 * stiffness[i] * stretch * stretch;
    }
    return v;
  }
  // The energy's gradient by fourth-order differences, and Newton on it (its Jacobian by
  // central differences of the gradient), from the hanging pose.
  Eigen::Vector3d gradient(const Eigen::Vector3d& x) const {
    Eigen::Vector3d out;
    const double h = 1e-3;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(j);
      out[j] = (8 * (energy(x + e) - energy(x - e)) - (energy(x + 2 * e) - energy(x - 2 * e))) /
               (12 * h);
    }
    return out;
  }
  Eigen::Vector3d minimum() const {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int it = 0; it < 50; ++it) {
      Eigen::Matrix3d hessian;
      for (int j = 0; j < 3; ++j) {
        const Eigen::Vector3d e = 1e-4 * Eigen::Vector3d::Unit(j);
        hessian.col(j) = (gradient(x + e) - gradient(x - e)) / 2e-4;
      }
      const Eigen::Vector3d step = -hessian.ldlt().solve(gradient(x));
      x += step;
      if (step.norm() < 1e-14) break;
    }
    return x;
  }

  Model model() const {
    Model m;
    const odyn::BodyId plate = m.add_body({.name = "plate",
                                           .mass = mass,
                                           .inertia = Eigen::Vector3d(0.1, 0.2, 0.25).asDiagonal(),
                                           .position = -ball});
    m.add(odyn::spatial::Spherical("ball", odyn::ground, Eigen::Vector3d::Zero(), plate, ball));
    for (std::size_t i = 0; i < 3; ++i)
      m.add(odyn::spatial::Tsda("spring" + std::to_string(i + 1), plate, on_plate[i], odyn::ground,
                                anchors[i],
                                {.stiffness = stiffness[i], .free_length = free_length[i]}));
    m.add(odyn::spatial::Gravity("gravity", {0.0, 0.0, -g}));
    return m;
  }
};

}  // namespace spring_plate
