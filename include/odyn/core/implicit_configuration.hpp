#pragma once
// The implicit position update of a BDF step for one body (or one free joint): the q with
//   q = beta + c T(q) w,
// T(q) w the configuration rate of the space (Spatial: the quaternion's rate q (0, w) / 2 in
// the body's axes; Planar: the angle's), which is affine in q, so that q solves one small
// linear system. Normalized afterwards (a unit quaternion).

#include <Eigen/Core>

#include "odyn/linalg/pivoted_lu.hpp"

namespace odyn {

template <class Space>
void implicit_configuration(const Eigen::Ref<const Eigen::Matrix<double, Space::nq, 1>>& beta,
                            double c, const Eigen::Matrix<double, Space::nv, 1>& w,
                            Eigen::Ref<Eigen::Matrix<double, Space::nq, 1>> q) {
  constexpr int nq = Space::nq;
  using Configuration = Eigen::Matrix<double, nq, 1>;
  using Square = Eigen::Matrix<double, nq, nq>;
  const Configuration offset = Space::configuration_rate(Configuration::Zero(), w);
  Square matrix = Square::Identity();
  for (int i = 0; i < nq; ++i)
    matrix.col(i) -= c * (Space::configuration_rate(Configuration::Unit(i), w) - offset);
  const Configuration right = beta + c * offset;
  q = solve_small<nq>(matrix, right);
  Space::normalize(q);
}

}  // namespace odyn
