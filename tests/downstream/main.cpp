// A downstream program against an installed odyn (find_package(odyn)): a pendulum with a
// damper written here, outside the library, as a new force element type.
#include <cmath>
#include <cstdio>
#include <odyn/odyn.hpp>

namespace sp = odyn::spatial;

// A force element is one class: its bodies, and the generalized force it puts on them.
struct AirDrag {
  using Space = odyn::Spatial;
  static constexpr int num_bodies = 1;
  std::string name_;
  std::array<odyn::BodyId, 1> bodies_;
  double coefficient;  // N s/m, on the centre of mass
  const std::string& name() const { return name_; }
  const std::array<odyn::BodyId, 1>& bodies() const { return bodies_; }
  void evaluate(const odyn::ElementInput<Space, 1>& in, odyn::ForceBlocks<Space, 1>& out) const {
    out.force[0].setZero();
    out.force[0].head<3>() = -coefficient * in.body(0).linear_velocity;
  }
};

int main() {
  using Model = sp::Model<sp::Revolute, sp::Gravity, AirDrag>;  // only what the scene needs
  Model model;
  const auto bob = model.add_body({.name = "bob",
                                   .mass = 1.0,
                                   .inertia = sp::Body::principal(1e-3, 1e-3, 1e-3),
                                   .position = {1.0, 0.0, 0.0}});
  const auto hinge = model.add(
      sp::Revolute("hinge", odyn::ground, {{0, 0, 0}, {0, 0, 1}}, bob, {{-1, 0, 0}, {0, 0, 1}}));
  model.add(sp::Gravity("gravity", {0.0, -9.81, 0.0}));
  model.add(AirDrag{"drag", {bob}, 0.05});

  odyn::Workspace<Model> ws(model);
  odyn::DynamicsSettings settings{.step = 1e-3, .t_end = 2.0, .output_interval = 0.5};
  // The integrator, chosen at compile time (odyn::simulate takes its name at run time instead).
  odyn::simulate_with<odyn::GeneralizedAlpha>(model, ws, settings, [&](const auto& state) {
    const auto reaction = odyn::reaction(model, state, hinge);
    std::printf(
        "t = %.1f s  angle = %+.4f rad  hinge force = (%+.3f, %+.3f) N\n", state.t,
        std::atan2(state.frames[bob.index].position.y(), state.frames[bob.index].position.x()),
        reaction.force.x(), reaction.force.y());
  });
  return 0;
}
