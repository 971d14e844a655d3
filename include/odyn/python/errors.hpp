#pragma once
// The library's exceptions in Python: each becomes the odyn._core class of its name
// (odyn.ModelError, AssemblyError, SolverError, Error), whichever module threw it.

#include <Python.h>

#include <pybind11/pybind11.h>

#include <exception>
#include <string>
#include <utility>

#include <odyn/core/errors.hpp>

namespace odyn::python {

namespace py = pybind11;

/// The name of the odyn._core class that a library exception becomes, and its message; a null
/// name for an exception that is not the library's.
inline std::pair<const char*, std::string> odyn_error(const std::exception_ptr& p) {
  try {
    std::rethrow_exception(p);
  } catch (const ModelError& e) {
    return {"ModelError", e.what()};
  } catch (const AssemblyError& e) {
    return {"AssemblyError", e.what()};
  } catch (const SolverError& e) {
    return {"SolverError", e.what()};
  } catch (const Error& e) {
    return {"Error", e.what()};
  } catch (...) {
    return {nullptr, {}};
  }
}

/// A pybind11 exception translator: sets the odyn._core error of a library exception, and
/// passes any other on.
inline void translate_odyn_error(std::exception_ptr p) {
  if (!p) return;
  const auto [name, message] = odyn_error(p);
  if (name == nullptr) std::rethrow_exception(p);
  const py::object error_class = py::module_::import("odyn._core").attr(name);
  PyErr_SetString(error_class.ptr(), message.c_str());
}

}  // namespace odyn::python
