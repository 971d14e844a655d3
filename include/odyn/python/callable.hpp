#pragma once
// The bridge that lets a Python callable act as an element's function: the callable, the body
// frames it is handed (NumPy views refreshed in place, so that a call allocates nothing) and the
// check of the numbers it returns.

#include <Python.h>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include <odyn/odyn.hpp>

namespace odyn::python {

namespace py = pybind11;

/// Numbers a Python callable returned (nested tuples or lists, or anything NumPy reads), checked
/// for their count and finiteness.
inline void read_numbers(py::handle value, double* out, int count, const std::string& what);

/// A body's frame as the Python callable sees it: a types.SimpleNamespace whose numpy arrays
/// (read-only) view a buffer that is refreshed before every call. Reusing one object makes a
/// call cost no allocation.
///   spatial: position (3), rotation (3 x 3), linear_velocity (3), angular_velocity (3, body)
///   planar:  position (2), rotation (2 x 2), linear_velocity (2) as arrays; angle and
///            angular_velocity as floats
template <class Space>
class FrameView;

template <>
class FrameView<Spatial> {
 public:
  FrameView();
  void load(const Spatial::Frame& frame);
  const py::object& object() const { return object_; }

 private:
  // Layout of the buffer: offsets of the arrays, then its size.
  static constexpr int position = 0, rotation = 3, linear_velocity = 12, angular_velocity = 15,
                       size = 18;
  double* data_ = nullptr;  // (size) owned by a capsule that the arrays keep alive
  py::object object_;
};

template <>
class FrameView<Planar> {
 public:
  FrameView();
  void load(const Planar::Frame& frame);
  const py::object& object() const { return object_; }

 private:
  static constexpr int position = 0, rotation = 2, linear_velocity = 6, size = 8;
  double* data_ = nullptr;
  py::object object_;
};

/// A Python callable and the frame views it is handed. Calls take the GIL; the destructor too,
/// so that an element may be dropped from any thread.
template <class Space>
class Callable {
 public:
  Callable(py::object function, int num_frames, std::string what);
  ~Callable();
  Callable(const Callable&) = delete;
  Callable& operator=(const Callable&) = delete;

  /// function(t, frame_0, ..., frame_{n-1}) with the frames loaded; the GIL must be held.
  py::object call_with_frames(double t, const typename Space::Frame* const* frames);
  /// function(a, b, c) for scalar arguments; the GIL must be held.
  py::object call_with_numbers(std::initializer_list<double> numbers);
  /// function(t, x, y) for two vectors of n numbers, passed as NumPy arrays; the GIL must be held.
  py::object call_with_vectors(double t, const double* x, const double* y, int n);
  const std::string& what() const { return what_; }

 private:
  /// Throws the exception the function raised, noted (PEP 678) with the element whose function
  /// raised it and, if finite, the time: its type, message and traceback stay the user's.
  [[noreturn]] void rethrow_noted(double t) const;

  py::object function_;
  std::vector<FrameView<Space>> views_;
  std::string what_;  // "point force 'push'": names the element in errors
};

namespace detail {
inline bool read_flat(PyObject* value, double* out, int count, int& filled) {
  // Fast path: tuples and lists of Python numbers (nested for several bodies).
  if (PyFloat_Check(value) || PyLong_Check(value)) {
    if (filled >= count) return false;
    out[filled++] = PyFloat_AsDouble(value);
    return !PyErr_Occurred();
  }
  if (PyTuple_Check(value) || PyList_Check(value)) {
    const Py_ssize_t n = PySequence_Fast_GET_SIZE(value);
    PyObject** items = PySequence_Fast_ITEMS(value);
    for (Py_ssize_t i = 0; i < n; ++i)
      if (!read_flat(items[i], out, count, filled)) return false;
    return true;
  }
  // Anything else that numpy reads as numbers (arrays, numpy scalars).
  auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array) {
    PyErr_Clear();
    return false;
  }
  if (filled + array.size() > count) return false;
  std::copy(array.data(), array.data() + array.size(), out + filled);
  filled += static_cast<int>(array.size());
  return true;
}
}  // namespace detail

inline void read_numbers(py::handle value, double* out, int count, const std::string& what) {
  int filled = 0;
  if (!detail::read_flat(value.ptr(), out, count, filled) || filled != count) {
    if (PyErr_Occurred()) throw py::error_already_set();
    throw py::type_error(what + ": the function must return " + std::to_string(count) +
                         (count == 1 ? " number" : " numbers") + ", got " +
                         std::string(py::repr(value)));
  }
  for (int i = 0; i < count; ++i)
    if (!std::isfinite(out[i]))
      throw py::value_error(what + ": the function returned a non-finite value (" +
                            std::string(py::repr(value)) + ")");
}

inline FrameView<Spatial>::FrameView() {
  data_ = new double[size]();
  py::capsule owner(data_, [](void* p) { delete[] static_cast<double*>(p); });
  auto view = [&](std::vector<py::ssize_t> shape, int offset) {
    py::array_t<double> array(shape, data_ + offset, owner);
    array.attr("flags").attr("writeable") = false;
    return array;
  };
  object_ = py::module_::import("types").attr("SimpleNamespace")(
      py::arg("position") = view({3}, position), py::arg("rotation") = view({3, 3}, rotation),
      py::arg("linear_velocity") = view({3}, linear_velocity),
      py::arg("angular_velocity") = view({3}, angular_velocity));
}

inline void FrameView<Spatial>::load(const Spatial::Frame& frame) {
  for (int i = 0; i < 3; ++i) {
    data_[position + i] = frame.position[i];
    for (int j = 0; j < 3; ++j) data_[rotation + 3 * i + j] = frame.rotation(i, j);  // by rows
    data_[linear_velocity + i] = frame.linear_velocity[i];
    data_[angular_velocity + i] = frame.angular_velocity[i];
  }
}

inline FrameView<Planar>::FrameView() {
  data_ = new double[size]();
  py::capsule owner(data_, [](void* p) { delete[] static_cast<double*>(p); });
  auto view = [&](std::vector<py::ssize_t> shape, int offset) {
    py::array_t<double> array(shape, data_ + offset, owner);
    array.attr("flags").attr("writeable") = false;
    return array;
  };
  object_ = py::module_::import("types").attr("SimpleNamespace")(
      py::arg("position") = view({2}, position), py::arg("angle") = 0.0,
      py::arg("rotation") = view({2, 2}, rotation),
      py::arg("linear_velocity") = view({2}, linear_velocity), py::arg("angular_velocity") = 0.0);
}

inline void FrameView<Planar>::load(const Planar::Frame& frame) {
  for (int i = 0; i < 2; ++i) {
    data_[position + i] = frame.position[i];
    for (int j = 0; j < 2; ++j) data_[rotation + 2 * i + j] = frame.rotation(i, j);  // by rows
    data_[linear_velocity + i] = frame.linear_velocity[i];
  }
  // Scalars are attributes of the namespace (Python floats: the cheapest for user code).
  const auto set = [&](const char* name, double value) {
    const py::object number = py::reinterpret_steal<py::object>(PyFloat_FromDouble(value));
    if (!number || PyObject_SetAttrString(object_.ptr(), name, number.ptr()) != 0)
      throw py::error_already_set();
  };
  set("angle", frame.angle);
  set("angular_velocity", frame.omega());
}

template <class Space>
Callable<Space>::Callable(py::object function, int num_frames, std::string what)
    : function_(std::move(function)),
      views_(static_cast<std::size_t>(num_frames)),
      what_(std::move(what)) {}

template <class Space>
Callable<Space>::~Callable() {
  py::gil_scoped_acquire gil;
  function_ = py::object();
  views_.clear();
}

template <class Space>
void Callable<Space>::rethrow_noted(double t) const {
  PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;
  PyErr_Fetch(&type, &value, &traceback);
  PyErr_NormalizeException(&type, &value, &traceback);
  if (value != nullptr) {
    if (traceback != nullptr) PyException_SetTraceback(value, traceback);
    const std::string note = "odyn: raised by the function of " + what_ +
                             (std::isfinite(t) ? ", at t = " + to_text(t) + " s" : "");
    PyObject* added = PyObject_CallMethod(value, "add_note", "s", note.c_str());
    if (added != nullptr)
      Py_DECREF(added);
    else
      PyErr_Clear();  // a Python without notes (before 3.11): the exception as it was
  }
  PyErr_Restore(type, value, traceback);
  throw py::error_already_set();
}

template <class Space>
py::object Callable<Space>::call_with_frames(double t, const typename Space::Frame* const* frames) {
  // Vectorcall with the argument slots on the stack: no tuple is built.
  std::array<PyObject*, 4> args{};  // slot 0 is scratch (PY_VECTORCALL_ARGUMENTS_OFFSET)
  py::object time = py::reinterpret_steal<py::object>(PyFloat_FromDouble(t));
  args[1] = time.ptr();
  for (std::size_t k = 0; k < views_.size(); ++k) {
    views_[k].load(*frames[k]);
    args[2 + k] = views_[k].object().ptr();
  }
  PyObject* result =
      PyObject_Vectorcall(function_.ptr(), args.data() + 1,
                          (1 + views_.size()) | PY_VECTORCALL_ARGUMENTS_OFFSET, nullptr);
  if (!result) rethrow_noted(t);
  return py::reinterpret_steal<py::object>(result);
}

template <class Space>
py::object Callable<Space>::call_with_numbers(std::initializer_list<double> numbers) {
  std::array<PyObject*, 4> args{};
  std::array<py::object, 3> owned;
  std::size_t n = 0;
  for (const double x : numbers) {
    owned[n] = py::reinterpret_steal<py::object>(PyFloat_FromDouble(x));
    args[1 + n] = owned[n].ptr();
    ++n;
  }
  PyObject* result = PyObject_Vectorcall(function_.ptr(), args.data() + 1,
                                         n | PY_VECTORCALL_ARGUMENTS_OFFSET, nullptr);
  if (!result) rethrow_noted(std::numeric_limits<double>::quiet_NaN());
  return py::reinterpret_steal<py::object>(result);
}

template <class Space>
py::object Callable<Space>::call_with_vectors(double t, const double* x, const double* y, int n) {
  const auto array = [n](const double* values) {
    py::array_t<double> out(n);
    std::copy(values, values + n, out.mutable_data());
    return out;
  };
  try {
    return function_(t, array(x), array(y));
  } catch (py::error_already_set& error) {
    error.restore();
    rethrow_noted(t);
  }
}

}  // namespace odyn::python
