#pragma once
// Distance constraint (massless rod): two points stay a fixed distance apart. 1 equation.

#include <cmath>

#include "odyn/spatial/pair_joint.hpp"
#include "odyn/spatial/primitives.hpp"

namespace odyn::spatial {

class Distance : public PairJoint {
 public:
  static constexpr int num_equations = 1;
  static constexpr ElementDescription description{
      "distance", "joint",
      "Distance (massless rod): the two points keep their distance. 1 equation.",
      parameters::distance};
  template <class Reader>
  static Distance from_parameters(Reader& r) {
    return parameters::from_point_pair<Distance, Eigen::Vector3d>(r,
                                                                  parameter<double>(r, "length"));
  }

  /// length <= 0 takes the distance at the initial pose.
  Distance(std::string name, BodyId body_a, const Eigen::Vector3d& point_a, BodyId body_b,
           const Eigen::Vector3d& point_b, double length = 0.0)
      : PairJoint(std::move(name), body_a, JointFrame{point_a}, body_b, JointFrame{point_b}),
        length_(length) {
    if (!std::isfinite(length_))
      throw ModelError(name_, "length must be finite, got " + to_text(length_));
  }

  double length() const { return length_; }

  void bind(const Input& in) {
    if (length_ > 0.0) return;
    length_ = (in.body(1).point(on_b_.point) - in.body(0).point(on_a_.point)).norm();
    if (!(length_ > 1e-12))
      throw ModelError(name_,
                       "the two points coincide at the initial pose, so the distance "
                       "would be zero; give a positive length or use a spherical joint");
  }

  void evaluate(const Input& in, BlocksOf<Distance>& out) const {
    primitive::distance(in.body(0), on_a_.point, in.body(1), on_b_.point, length_, out, 0);
    out.phi_t.setZero();
  }

  Eigen::Matrix<double, 1, 1> gamma(const Input& in) const {
    return Eigen::Matrix<double, 1, 1>(
        primitive::distance_gamma(in.body(0), on_a_.point, in.body(1), on_b_.point, length_));
  }

  void add_geometric_stiffness(const Input& in, const Eigen::Matrix<double, 1, 1>& lambda,
                               GeometricStiffness<Space, 2>& out) const {
    primitive::distance_stiffness(in.body(0), on_a_.point, in.body(1), on_b_.point, length_,
                                  lambda[0], out);
  }

 private:
  double length_;
};
static_assert(Constraint<Distance>);

}  // namespace odyn::spatial
