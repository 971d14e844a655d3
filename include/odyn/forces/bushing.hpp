#pragma once
// A bushing in either space: its law (forces/bushing_law.hpp) acting between a frame on body a
// and one on body b. What differs between the spaces, how the frames' displacement is measured
// and how the law's generalized force acts on the bodies, comes from a Geometry
// (spatial/bushing.hpp, planar/bushing.hpp) with
//     Pair, JointFrame, components, summary        the pair joint it builds on, and so on
//     with_defaults(frame)                         the frame's axes left out made the body's
//     displacement(pair, in) -> Law::Displacement  x and x' of frame b relative to frame a
//     apply(pair, in, displacement, g, out)        the generalized forces of g on a and b
//     outputs                                      x, x' and g, one output per component
// Stiffness and damping blocks for implicit integrators come by central differences.

#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/difference_jacobians.hpp"
#include "odyn/core/element.hpp"
#include "odyn/forces/bushing_law.hpp"

namespace odyn {

template <class Geometry>
class BushingT : public Geometry::Pair {
 public:
  using Pair = typename Geometry::Pair;
  using Space = typename Pair::Space;
  using Input = typename Pair::Input;
  using JointFrame = typename Geometry::JointFrame;
  using Law = BushingLaw<Geometry::components>;
  using Displacement = typename Law::Displacement;

  static constexpr std::array<Parameter, 9> parameter_list =
      join(parameters::bushing_frames, parameters::bushing_law);
  static constexpr ElementDescription description{"bushing", "force", Geometry::summary,
                                                  parameter_list, Geometry::outputs};
  template <class Reader>
  static BushingT from_parameters(Reader& r) {
    return parameters::from_frame_pair<BushingT, JointFrame>(r, Law::from_parameters(r));
  }

  BushingT(std::string name, BodyId body_a, const JointFrame& on_a, BodyId body_b,
           const JointFrame& on_b, Law law)
      : Pair(std::move(name), body_a, Geometry::with_defaults(on_a), body_b,
             Geometry::with_defaults(on_b)),
        law_(std::move(law)) {
    law_.check(this->name());
  }

  /// The displacement x of frame b relative to frame a and its rate x'.
  Displacement displacement(const Input& in) const { return Geometry::displacement(*this, in); }

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    const Displacement x = displacement(in);
    Geometry::apply(*this, in, x, law_.force(in.t, x.x, x.rate), out);
  }

  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    difference_jacobians(*this, in, out);
  }

  double potential_energy(const Input& in) const {
    return law_.potential_energy(displacement(in).x);
  }

  /// x, x' and the law's g, component by component.
  std::array<double, 3 * Geometry::components> outputs(const Input& in) const {
    const Displacement x = displacement(in);
    const typename Law::Vector g = law_.force(in.t, x.x, x.rate);
    std::array<double, 3 * Geometry::components> out;
    constexpr int n = Geometry::components;
    for (int i = 0; i < n; ++i) out[i] = x.x[i], out[n + i] = x.rate[i], out[2 * n + i] = g[i];
    return out;
  }

  const Law& law() const { return law_; }

 private:
  Law law_;
};

}  // namespace odyn
