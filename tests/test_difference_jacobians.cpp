// Stiffness and damping by central differences (odyn/core/difference_jacobians.hpp) against an
// element's exact blocks: a spring-damper between the centres of mass of two bodies, spatial and
// planar, at random poses and velocities. Its own jacobians() are exact there for the spring
// (the lever arms vanish) and for the damping block; they leave out how the damper's force
// turns with the bodies' positions, so the stiffness is compared without a damper.

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <random>

#include <odyn/core/difference_jacobians.hpp>
#include <odyn/odyn.hpp>

namespace test_difference_jacobians {

template <class Space, class Tsda>
void check_spring(std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const auto vector = [&](auto size) {
    Eigen::Matrix<double, decltype(size)::value, 1> v;
    for (int i = 0; i < v.size(); ++i) v[i] = uniform(random);
    return v;
  };
  std::array<typename Space::Frame, 2> frames;
  for (auto& frame : frames) {
    typename Space::Configuration q;
    if constexpr (Space::nq == 7) {
      Eigen::Quaterniond r(vector(std::integral_constant<int, 4>{}));
      r.normalize();
      q << 2.0 * vector(std::integral_constant<int, 3>{}), r.w(), r.x(), r.y(), r.z();
    } else {
      q << 2.0 * vector(std::integral_constant<int, 3>{});
    }
    Space::make_frame(q, 3.0 * vector(std::integral_constant<int, Space::nv>{}), frame);
  }
  const typename Space::Vector origin = Space::Vector::Zero();
  const odyn::ElementInput<Space, 2> in{{&frames[0], &frames[1]}, 0.3};
  odyn::ForceBlocks<Space, 2> exact, differences;
  const Tsda spring("spring", odyn::BodyId{1}, origin, odyn::BodyId{2}, origin,
                    {2.0e4, 0.0, 0.4, {}});
  spring.jacobians(in, exact);
  odyn::difference_jacobians(spring, in, differences);
  INFO("seed " << seed << "\nexact stiffness\n"
               << exact.stiffness << "\ndifferences\n"
               << differences.stiffness);
  CHECK((differences.stiffness - exact.stiffness).cwiseAbs().maxCoeff() <
        1e-6 * exact.stiffness.cwiseAbs().maxCoeff());
  CHECK(differences.damping.cwiseAbs().maxCoeff() < 1e-6);
  const Tsda damper("damper", odyn::BodyId{1}, origin, odyn::BodyId{2}, origin,
                    {2.0e4, 35.0, 0.4, {}});
  damper.jacobians(in, exact);
  odyn::difference_jacobians(damper, in, differences);
  CHECK((differences.damping - exact.damping).cwiseAbs().maxCoeff() <
        1e-6 * exact.damping.cwiseAbs().maxCoeff());
  // The frames handed in are left as they were.
  CHECK(&in.body(0) == &frames[0]);
}

TEST_CASE("Stiffness and damping by differences match a spring's exact blocks",
          "[difference_jacobians]") {
  for (const std::uint32_t seed : {3u, 17u, 40u}) {
    check_spring<odyn::Spatial, odyn::spatial::Tsda>(seed);
    check_spring<odyn::Planar, odyn::planar::Tsda>(seed);
  }
}

TEST_CASE("Stiffness by differences turns with the body: a point force, in body and global axes",
          "[difference_jacobians]") {
  // A force f at body point s: in body axes Q = (R f, s x f), so -dQ/dq has R [f]x in its
  // force-rotation block; in global axes Q = (f, s x R^T f), whose rotation block is
  // -[s]x [R^T f]x (rotations about body axes, R -> R (I + [dtheta]x)).
  const Eigen::Quaterniond r = Eigen::Quaterniond(0.8, 0.1, -0.5, 0.3).normalized();
  odyn::Spatial::Configuration q;
  q << 0.4, -1.2, 0.7, r.w(), r.x(), r.y(), r.z();
  odyn::Spatial::Velocity v;
  v << 0.3, 0.2, -0.1, 1.5, -0.7, 2.0;
  odyn::Spatial::Frame frame;
  odyn::Spatial::make_frame(q, v, frame);
  const odyn::ElementInput<odyn::Spatial, 1> in{{&frame}, 0.0};
  const Eigen::Vector3d s(0.3, -0.2, 0.5), f(4.0, -1.0, 2.5);
  const auto skew = [](const Eigen::Vector3d& x) { return odyn::skew(x); };
  const Eigen::Matrix3d rotation = r.toRotationMatrix();
  for (const odyn::Axes axes : {odyn::Axes::body, odyn::Axes::global}) {
    const odyn::spatial::PointForce force("push", odyn::BodyId{1}, s, f, axes);
    odyn::ForceBlocks<odyn::Spatial, 1> differences;
    odyn::difference_jacobians(force, in, differences);
    Eigen::Matrix<double, 6, 6> expected = Eigen::Matrix<double, 6, 6>::Zero();
    if (axes == odyn::Axes::body)
      expected.topRightCorner<3, 3>() = rotation * skew(f);
    else
      expected.bottomRightCorner<3, 3>() = -skew(s) * skew(rotation.transpose() * f);
    INFO("differences\n" << differences.stiffness << "\nexpected\n" << expected);
    CHECK((differences.stiffness - expected).cwiseAbs().maxCoeff() < 1e-8);
    CHECK(differences.damping.cwiseAbs().maxCoeff() < 1e-8);
  }
}

}  // namespace test_difference_jacobians
