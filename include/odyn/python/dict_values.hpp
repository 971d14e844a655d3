#pragma once
// Values from the dict the Python layer checked (python/odyn/_schema.py): numbers, names,
// motions, and scalar functions that are Python callables.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>
#include <odyn/python/callable.hpp>

namespace odyn::python {

inline double number(const py::dict& d, const char* key) {
  return d[key].cast<double>();
}
inline std::string text(const py::dict& d, const char* key) {
  return d[key].cast<std::string>();
}

namespace detail {
/// A scalar function of one or three numbers from a Python callable.
template <class... Args>
std::function<double(Args...)> scalar_function(py::object f, const std::string& what) {
  auto callable = std::make_shared<Callable<Spatial>>(std::move(f), 0, what);
  return [callable](Args... args) {
    py::gil_scoped_acquire gil;
    double value = 0.0;
    read_numbers(callable->call_with_numbers({static_cast<double>(args)...}), &value, 1,
                 callable->what());
    return value;
  };
}
}  // namespace detail

inline std::function<double(double, double, double)> scalar_function3(py::object f,
                                                                      const std::string& what) {
  return detail::scalar_function<double, double, double>(std::move(f), what);
}

inline Motion motion(const py::dict& d, const std::string& what) {
  const py::dict m = d["motion"].cast<py::dict>();
  const std::string type = text(m, "type");
  if (type == "constant_velocity")
    return Motion::constant_velocity(number(m, "rate"), number(m, "start"));
  if (type == "polynomial")
    return Motion::polynomial(m["coefficients"].cast<std::vector<double>>());
  if (type == "harmonic")
    return Motion::harmonic(number(m, "amplitude"), number(m, "frequency"), number(m, "phase"),
                            number(m, "offset"));
  if (type == "function")
    return {detail::scalar_function<double>(m["position"], what + " motion position"),
            detail::scalar_function<double>(m["velocity"], what + " motion velocity"),
            detail::scalar_function<double>(m["acceleration"], what + " motion acceleration")};
  throw ModelError(what, "unknown motion type '" + type + "'");
}

}  // namespace odyn::python
