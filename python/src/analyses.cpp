// odyn._core: the spatial model's analyses other than the dynamic one (dynamics.cpp), and the
// integrators the library knows by name.

#include <odyn/python/analyses.hpp>

#include "bindings.hpp"

namespace odyn::python {

void bind_spatial_analyses(py::module_& m) {
  analysis::bind_kinematics<SpatialBox>(m);
  analysis::bind_statics<SpatialBox>(m);
}

void bind_integrators(py::module_& m) {
  m.def(
      "integrators",
      [] {
        std::vector<std::pair<std::string, std::string>> out;
        for (const auto& [name, what] : odyn::integrator_names()) out.emplace_back(name, what);
        return out;
      },
      "The integrators that simulate knows by name: a list of (name, description), from the "
      "C++ library's odyn::integrator_names().");
  m.def(
      "default_settings",
      [] {
        const DynamicsSettings s;
        const auto& ga = s.generalized_alpha;
        const auto& dp = s.dormand_prince;
        py::dict out;
        out["run"] = py::dict(py::arg("step") = s.step, py::arg("rtol") = s.rtol,
                              py::arg("atol") = s.atol, py::arg("max_step") = s.max_step);
        out["generalized_alpha"] =
            py::dict(py::arg("rho_inf") = ga.rho_inf, py::arg("newton_rtol") = ga.newton_rtol,
                     py::arg("newton_atol") = ga.newton_atol,
                     py::arg("constraint_tolerance") = ga.constraint_tolerance,
                     py::arg("max_iterations") = ga.max_iterations,
                     py::arg("reuse_iterations") = ga.reuse_iterations,
                     py::arg("adaptive") = ga.adaptive, py::arg("max_growth") = ga.max_growth,
                     py::arg("consistent_outputs") = ga.consistent_outputs);
        out["dormand_prince"] =
            py::dict(py::arg("projection_tolerance") = dp.projection_tolerance,
                     py::arg("max_projection_iterations") = dp.max_projection_iterations,
                     py::arg("singular_threshold") = dp.singular_threshold);
        out["bdf"] = py::dict(py::arg("max_order") = s.bdf.max_order,
                              py::arg("local_error_fraction") = s.bdf.local_error_fraction,
                              py::arg("newton_tolerance") = s.bdf.newton_tolerance,
                              py::arg("constraint_tolerance") = s.bdf.constraint_tolerance,
                              py::arg("max_iterations") = s.bdf.max_iterations,
                              py::arg("reuse_iterations") = s.bdf.reuse_iterations,
                              py::arg("reuse_band") = s.bdf.reuse_band,
                              py::arg("max_growth") = s.bdf.max_growth);
        out["adams"] =
            py::dict(py::arg("order") = s.adams.order,
                     py::arg("projection_tolerance") = s.adams.projection_tolerance,
                     py::arg("velocity_tolerance") = s.adams.velocity_tolerance,
                     py::arg("max_projection_iterations") = s.adams.max_projection_iterations);
        out["assembly"] = py::dict(py::arg("tolerance") = s.assembly.tolerance,
                                   py::arg("max_iterations") = s.assembly.max_iterations,
                                   py::arg("warn_translation") = s.assembly.warn_translation,
                                   py::arg("warn_rotation") = s.assembly.warn_rotation);
        return out;
      },
      "The C++ defaults of DynamicsSettings, by section (run, generalized_alpha, "
      "dormand_prince, bdf, adams, assembly): the typed settings of odyn.settings mirror them.");
}

}  // namespace odyn::python
