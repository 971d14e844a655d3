// A time step allocates nothing: every buffer lives in the workspace and the integrator,
// sized once. The count: in a plain build, global operator new is replaced here; under
// AddressSanitizer, which owns operator new and malloc, its allocator calls a hook on every
// heap allocation (new included), so the same test runs in the sanitizer build too.

#include <atomic>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <vector>

#include "engine_model.hpp"

namespace test_allocation {
std::atomic<long> allocations{0};
std::atomic<bool> counting{false};
}  // namespace test_allocation

// GCC says __SANITIZE_ADDRESS__; Clang before 17 only answers __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define ODYN_TEST_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ODYN_TEST_UNDER_ASAN 1
#endif
#endif

#ifdef ODYN_TEST_UNDER_ASAN
// From <sanitizer/allocator_interface.h>, which GCC does not ship; libasan defines it.
using MallocHook = void (*)(const volatile void*, std::size_t);
using FreeHook = void (*)(const volatile void*);
extern "C" int __sanitizer_install_malloc_and_free_hooks(MallocHook, FreeHook);

namespace test_allocation {
void on_malloc(const volatile void*, std::size_t) {
  if (counting) ++allocations;
}
void on_free(const volatile void*) {}
// Installed before main runs, once for the whole test program.
const int hooks_installed = __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
}  // namespace test_allocation
#else
// GCC cannot see that these replacements pair malloc with free.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  if (test_allocation::counting) ++test_allocation::allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop
#endif

namespace test_allocation {

TEST_CASE("the allocation count sees a heap allocation", "[workspace]") {
  allocations = 0;
  counting = true;
  static std::vector<double> buffer;  // static: the allocation cannot be optimized away
  buffer.assign(100, 1.0);
  counting = false;
  buffer = {};
  CHECK(allocations >= 1);
}

TEST_CASE("a time step allocates nothing, events and restarts included", "[workspace]") {
  engine::Engine e = engine::build();
  odyn::Workspace<engine::Model> ws(e.model);
  odyn::assemble(e.model, ws);
  odyn::GeneralizedAlpha<engine::Model> integrator(e.model, ws);
  for (int i = 0; i < 10; ++i) integrator.step(1e-4);  // warm up
  allocations = 0;
  counting = true;
  // 0.05 s takes the crank through ignition: event location and a restart happen here.
  odyn::advance_to(e.model, ws, integrator, 0.05, 1e-4);
  counting = false;
  CHECK(integrator.statistics().events >= 2);
  CHECK(allocations == 0);
}

TEST_CASE("a BDF step allocates nothing, events and restarts included", "[workspace][bdf]") {
  engine::Engine e = engine::build();
  odyn::Workspace<engine::Model> ws(e.model);
  odyn::assemble(e.model, ws);
  odyn::Bdf<engine::Model> integrator(e.model, ws, {}, {.rtol = 1e-8, .atol = 1e-8});
  odyn::advance_to(e.model, ws, integrator, 0.005, 1e-4);  // warm up
  allocations = 0;
  counting = true;
  odyn::advance_to(e.model, ws, integrator, 0.05, 1e-4);
  counting = false;
  CHECK(integrator.statistics().events >= 2);
  CHECK(allocations == 0);
}

/// The engine from 5 ms to 50 ms, through ignition (an event and a restart), counting the
/// allocations after a warm-up.
template <class Integrator, class Engine = engine::Engine>
void check_engine_run(const typename Integrator::Settings& settings, odyn::StepControl control) {
  Engine e;
  if constexpr (std::is_same_v<Engine, engine::Engine>)
    e = engine::build();
  else
    e = engine::planar::build();
  odyn::Workspace<typename Engine::Model> ws(e.model);
  odyn::assemble(e.model, ws);
  Integrator integrator(e.model, ws, settings, control);
  odyn::advance_to(e.model, ws, integrator, 0.005, 1e-4);  // warm up
  allocations = 0;
  counting = true;
  odyn::advance_to(e.model, ws, integrator, 0.05, 1e-4);
  if constexpr (requires { integrator.refresh_blocks(); }) integrator.refresh_blocks();
  counting = false;
  CHECK(integrator.statistics().events >= 2);
  CHECK(allocations == 0);
}

TEST_CASE("a dop853 step allocates nothing, in absolute and in joint coordinates",
          "[workspace][dop853][joint]") {
  const odyn::StepControl control{.rtol = 1e-8, .atol = 1e-8, .first_step = 1e-5};
  check_engine_run<odyn::DormandPrince853<engine::Model>>({}, control);
  check_engine_run<odyn::JointDormandPrince853<engine::Model>>({}, control);
}

TEST_CASE("an Adams step allocates nothing, in absolute and in joint coordinates",
          "[workspace][adams][joint]") {
  // The restart at ignition runs the start-up steps (dopri5) too.
  check_engine_run<odyn::AdamsBashforth<engine::Model>>({.order = 5}, {});
  check_engine_run<odyn::JointAdamsBashforth<engine::Model>>({.order = 5}, {});
}

TEST_CASE("generalized-alpha and BDF steps allocate nothing in joint coordinates",
          "[workspace][joint]") {
  check_engine_run<odyn::JointGeneralizedAlpha<engine::Model>>({}, {});
  check_engine_run<odyn::JointBdf<engine::Model>>({}, {.rtol = 1e-8, .atol = 1e-8});
}

TEST_CASE("planar joint coordinates' steps allocate nothing", "[workspace][joint][planar]") {
  using Planar = engine::planar::Engine;
  using Model = engine::planar::Model;
  check_engine_run<odyn::JointDormandPrince853<Model>, Planar>(
      {}, {.rtol = 1e-8, .atol = 1e-8, .first_step = 1e-5});
  check_engine_run<odyn::JointGeneralizedAlpha<Model>, Planar>({}, {});
  check_engine_run<odyn::JointBdf<Model>, Planar>({}, {.rtol = 1e-8, .atol = 1e-8});
}

TEST_CASE(
    "dop853, generalized-alpha and BDF steps allocate nothing in joint coordinates' "
    "recursive passes",
    "[workspace][dop853][joint]") {
  // Ten ball-jointed links, the last tied back to the ground by a distance: 30 rates and one
  // closure, above the size at which the whole saddle-point matrix is formed.
  namespace sp = odyn::spatial;
  using Model = sp::Model<sp::Spherical, sp::Distance, sp::Gravity>;
  Model model;
  odyn::BodyId previous = odyn::ground;
  for (int i = 0; i < 10; ++i) {
    const odyn::BodyId body = model.add_body({.name = "link" + std::to_string(i),
                                              .mass = 1.0,
                                              .inertia = sp::Body::principal(0.01, 0.1, 0.1),
                                              .position = {0.5 + i, 0.0, 0.0}});
    model.add(sp::Spherical(
        "joint" + std::to_string(i), previous,
        previous.is_ground() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.5, 0.0, 0.0), body,
        {-0.5, 0.0, 0.0}));
    previous = body;
  }
  model.add(sp::Distance("tie", previous, {0.5, 0.0, 0.0}, odyn::ground, {11.0, 0.0, -1.0}));
  model.add(sp::Gravity("gravity", {0.0, 0.0, -9.81}));
  const auto check = [&]<class Integrator>(Integrator*) {
    odyn::Workspace<Model> ws(model);
    odyn::assemble(model, ws);
    Integrator integrator(model, ws, {}, {.rtol = 1e-8, .atol = 1e-8});
    odyn::advance_to(model, ws, integrator, 0.01, 1e-3);  // warm up
    allocations = 0;
    counting = true;
    odyn::advance_to(model, ws, integrator, 0.1, 1e-3);
    integrator.refresh_blocks();
    counting = false;
    CHECK(integrator.statistics().steps > 5);
    CHECK(allocations == 0);
  };
  check(static_cast<odyn::JointDormandPrince853<Model>*>(nullptr));
  check(static_cast<odyn::JointGeneralizedAlpha<Model>*>(nullptr));
  check(static_cast<odyn::JointBdf<Model>*>(nullptr));
}

TEST_CASE("a time step allocates nothing on the sparse paths (CHOLMOD's Schur complement, KLU)",
          "[workspace][sparse]") {
  // The engine's generalized-alpha run with each sparse factorization forced; under the
  // sanitizer the count includes the SuiteSparse libraries' own mallocs.
  for (const odyn::LinearSolver choice : {odyn::LinearSolver::cholmod, odyn::LinearSolver::klu}) {
    INFO(odyn::linear_solver_name(choice));
    engine::Engine e = engine::build();
    odyn::Workspace<engine::Model> ws(e.model);
    odyn::assemble(e.model, ws);
    odyn::GeneralizedAlpha<engine::Model> integrator(e.model, ws, {.linear_solver = choice});
    for (int i = 0; i < 10; ++i) integrator.step(1e-4);  // warm up
    allocations = 0;
    counting = true;
    odyn::advance_to(e.model, ws, integrator, 0.05, 1e-4);
    counting = false;
    CHECK(integrator.statistics().events >= 2);
    CHECK(allocations == 0);
  }
}

}  // namespace test_allocation
