#pragma once
// The element catalogue of a compiled model type: each element type that describes itself
// (odyn/core/description.hpp) is added from a Python dict by its own from_parameters, through
// a DictReader that turns the dict's values into the C++ types the element asks for. Nothing
// here names an element type: a new element in a model's type list is all it takes.

#include <Python.h>

#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include <odyn/python/dict_values.hpp>
#include <odyn/python/models.hpp>

namespace odyn::python {

namespace detail {

template <class T>
struct IsFixedVector : std::false_type {};
template <int N>
struct IsFixedVector<Eigen::Matrix<double, N, 1>> : std::true_type {};

template <class T>
struct IsFixedSquare : std::false_type {};
template <int N>
struct IsFixedSquare<Eigen::Matrix<double, N, N>> : std::bool_constant<(N > 1)> {};

/// std::function<V(double, const V&, const V&)>: a law of a displacement and its rate.
template <class T>
struct VectorLaw : std::false_type {};
template <int N>
struct VectorLaw<std::function<Eigen::Matrix<double, N, 1>(
    double, const Eigen::Matrix<double, N, 1>&, const Eigen::Matrix<double, N, 1>&)>>
    : std::true_type {
  using Vector = Eigen::Matrix<double, N, 1>;
};

/// std::function<Vector(double, const Frame&)>: a function of time and one body's frame.
template <class T>
struct FrameFunction : std::false_type {};
template <class Vector, class Frame>
struct FrameFunction<std::function<Vector(double, const Frame&)>> : std::true_type {
  using Result = Vector;
  using Space = std::conditional_t<std::is_same_v<Frame, Planar::Frame>, Planar, Spatial>;
};

template <class T>
struct IsJointReference : std::false_type {};
template <class F>
struct IsJointReference<parameters::JointReference<F>> : std::true_type {
  using Frame = F;
};

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

template <class T>
inline constexpr bool always_false = false;

}  // namespace detail

/// Reads an element's parameters from the dict the Python layer checked (python/odyn/_schema.py),
/// as the types the element's from_parameters asks for, and remembers which keys it read so
/// that `refuse_unread` can name a key no parameter uses.
template <class M>
class DictReader {
 public:
  DictReader(const M& model, const py::dict& values, const ElementDescription& description)
      : model_(model), values_(values), description_(description) {
    what_ = std::string(description.type) + " '" +
            (values.contains("name") ? py::str(values["name"]).cast<std::string>() : "?") + "'";
  }

  template <class T>
  T get(const char* key) {
    const py::object value = item(key);
    if constexpr (std::is_same_v<T, py::object>) {
      return value;
    } else if constexpr (std::is_same_v<T, std::string>) {
      return value.cast<std::string>();
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      return value.cast<std::vector<std::string>>();
    } else if constexpr (std::is_same_v<T, double>) {
      return value.cast<double>();
    } else if constexpr (detail::IsOptional<T>::value) {
      if (value.is_none()) return std::nullopt;
      return get<typename T::value_type>(key);
    } else if constexpr (std::is_same_v<T, JointCoordinateKind>) {
      const std::string kind = value.cast<std::string>();
      if (kind != "angle" && kind != "slide")
        throw ModelError(what_, std::string(key) + " is '" + kind + "'; expected angle or slide");
      return kind == "angle" ? JointCoordinateKind::angle : JointCoordinateKind::slide;
    } else if constexpr (std::is_same_v<T, bool>) {
      return value.cast<bool>();
    } else if constexpr (std::is_same_v<T, BodyId>) {
      return model_.body(value.cast<std::string>());
    } else if constexpr (std::is_same_v<T, Axes>) {
      return !value.is_none() && value.cast<std::string>() == "body" ? Axes::body : Axes::global;
    } else if constexpr (std::is_same_v<T, Motion>) {
      return motion(values_, what_);
    } else if constexpr (std::is_same_v<T, sp::JointFrame> || std::is_same_v<T, pl::JointFrame>) {
      return joint_frame<T>(value);
    } else if constexpr (detail::IsJointReference<T>::value) {
      // A joint added before, which the Python layer resolved into its bodies and frames.
      using Frame = typename detail::IsJointReference<T>::Frame;
      const py::dict d = value.cast<py::dict>();
      return T{model_.body(d["body_a"].cast<std::string>()), joint_frame<Frame>(d["on_a"]),
               model_.body(d["body_b"].cast<std::string>()), joint_frame<Frame>(d["on_b"])};
    } else if constexpr (detail::IsFixedSquare<T>::value) {
      return value.cast<T>();  // the Python layer made a diagonal a full matrix
    } else if constexpr (detail::VectorLaw<T>::value) {
      if (value.is_none()) return {};
      return vector_law<typename detail::VectorLaw<T>::Vector>(value, key);
    } else if constexpr (detail::IsFixedVector<T>::value) {
      if constexpr (T::RowsAtCompileTime == 1) {
        if (PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()))
          return T::Constant(value.cast<double>());  // a planar torque is a number
      }
      return value.cast<T>();
    } else if constexpr (std::is_same_v<T, std::function<double(double, double, double)>>) {
      if (value.is_none()) return {};
      return scalar_function3(value, what_ + " " + key);
    } else if constexpr (detail::FrameFunction<T>::value) {
      return frame_function<T>(value);
    } else {
      static_assert(detail::always_false<T>, "DictReader cannot read this parameter type");
    }
  }

  /// True if the value of `key` is a Python callable.
  bool is_function(const char* key) {
    return values_.contains(key) && PyCallable_Check(values_[key].ptr());
  }

  /// Refuses a key that names no parameter the element read, listing the valid ones.
  void refuse_unread() const {
    for (const auto& item : values_) {
      const std::string key = py::str(item.first).cast<std::string>();
      bool used = false;
      for (const std::string& read : read_) used = used || read == key;
      if (used) continue;
      std::string valid;
      for (const Parameter& p : description_.parameters)
        valid += std::string(valid.empty() ? "" : ", ") + p.name;
      throw ModelError(what_, "unknown parameter '" + key + "'; expected one of " + valid);
    }
  }

 private:
  static bool present(const py::dict& d, const char* key) {
    return d.contains(key) && !d[key].is_none();
  }
  template <class Frame>
  static Frame joint_frame(const py::object& value) {
    Frame frame;  // a planar axis left out stays zero: the other body's at the start
    if (value.is_none()) return frame;
    const py::dict d = value.cast<py::dict>();
    using Vector = decltype(frame.point);
    if (present(d, "point")) frame.point = d["point"].cast<Vector>();
    if (present(d, "axis")) frame.axis = d["axis"].cast<Vector>();
    if constexpr (std::is_same_v<Frame, sp::JointFrame>)
      if (present(d, "reference")) frame.reference = d["reference"].cast<Vector>();
    return frame;
  }
  bool declares(const char* key) const {
    for (const Parameter& p : description_.parameters)
      if (std::string(p.name) == key) return true;
    return false;
  }
  py::object item(const char* key) {
    if (!declares(key))
      throw Error(what_ + ": reads parameter '" + key +
                  "', which its description does not list (a bug in the element type)");
    read_.emplace_back(key);
    if (!values_.contains(key)) return py::none();
    return values_[key];
  }

  /// law(t, x, x') -> V from a Python callable taking (t, x, x') with NumPy arrays.
  template <class V>
  std::function<V(double, const V&, const V&)> vector_law(py::object f, const char* key) const {
    auto callable = std::make_shared<Callable<Spatial>>(std::move(f), 0, what_ + " " + key);
    return [callable](double t, const V& x, const V& rate) {
      V value;
      py::gil_scoped_acquire gil;
      read_numbers(callable->call_with_vectors(t, x.data(), rate.data(), int(V::RowsAtCompileTime)),
                   value.data(), int(V::RowsAtCompileTime), callable->what());
      return value;
    };
  }

  template <class F>
  F frame_function(py::object f) const {
    using Traits = detail::FrameFunction<F>;
    using Space = typename Traits::Space;
    using Result = typename Traits::Result;
    auto callable = std::make_shared<Callable<Space>>(std::move(f), 1, what_);
    return [callable](double t, const typename Space::Frame& frame) {
      const typename Space::Frame* frames[1] = {&frame};
      Result value;
      py::gil_scoped_acquire gil;
      read_numbers(callable->call_with_frames(t, frames), value.data(),
                   static_cast<int>(value.size()), callable->what());
      return value;
    };
  }

  const M& model_;
  const py::dict& values_;
  const ElementDescription& description_;
  std::string what_;
  std::vector<std::string> read_;
};

/// The name of element type E as Python and scene files know it.
template <class E>
constexpr const char* element_type_name() {
  if constexpr (Described<E>)
    return E::description.type;
  else
    return "signal_watch";  // internal: never added by the user
}

/// What each model type of the bindings holds, and how to add each described element.
template <class M>
struct Catalogue;
template <class Body, class... Elements>
struct Catalogue<odyn::Model<Body, Elements...>> {
  using ModelType = odyn::Model<Body, Elements...>;
  using Box = ModelBox<ModelType>;
  using Adder = void (*)(Box&, const py::dict&);

  /// Names of the element types, in the order of the model's element list.
  static constexpr std::array<const char*, sizeof...(Elements)> type_names{
      element_type_name<Elements>()...};

  /// Type name -> how to add one from a dict; user forces choose their body count.
  static const std::unordered_map<std::string, Adder>& adders() {
    static const std::unordered_map<std::string, Adder> table = [] {
      std::unordered_map<std::string, Adder> out;
      (register_type<Elements>(out), ...);
      return out;
    }();
    return table;
  }

  /// The descriptions of the element types a user may add, each type once, in list order.
  static std::vector<const ElementDescription*> descriptions() {
    std::vector<const ElementDescription*> out;
    auto add = [&]<class E>(std::type_identity<E>) {
      if constexpr (Described<E>) {
        for (const ElementDescription* d : out)
          if (std::string(d->type) == E::description.type) return;
        out.push_back(&E::description);
      }
    };
    (add(std::type_identity<Elements>{}), ...);
    return out;
  }

 private:
  template <class E>
  static void register_type(std::unordered_map<std::string, Adder>& out) {
    if constexpr (Described<E>) {
      static_assert(is_well_formed(E::description), "a parameter of unknown kind or twice named");
      static_assert(!ListsOutputsItDoesNotCompute<E>,
                    "the description lists outputs that outputs(in) does not return");
      static_assert(!ListsStateItDoesNotRecord<E>,
                    "the description lists state fields that state_values does not return");
      if constexpr (IsUserForce<E>::value)
        out.emplace(E::description.type, &add_user_force);
      else if constexpr (IsUserConstraint<E>::value)
        out.emplace(E::description.type, &add_user_constraint);
      else
        out.emplace(E::description.type, &add_described<E>);
    }
  }

  template <class E>
  static void add_described(Box& box, const py::dict& values) {
    DictReader<ModelType> reader(box.model, values, E::description);
    E element = E::from_parameters(reader);
    reader.refuse_unread();
    box.model.add(std::move(element));
  }

  template <class E>
  struct IsUserForce : std::false_type {};
  template <class S, int N>
  struct IsUserForce<UserForceT<S, N>> : std::true_type {};

  template <class E>
  struct IsUserConstraint : std::false_type {};
  template <class S>
  struct IsUserConstraint<UserConstraintT<S>> : std::true_type {};

  static void add_user_constraint(Box& box, const py::dict& values) {
    using Space = typename ModelType::Space;
    DictReader<ModelType> reader(box.model, values, UserConstraintT<Space>::description);
    const auto name = parameter<std::string>(reader, "name");
    std::vector<BodyId> bodies;
    for (const std::string& body : reader.template get<std::vector<std::string>>("bodies"))
      bodies.push_back(box.model.body(body));
    std::array<py::object, 3> functions{reader.template get<py::object>("function"),
                                        reader.template get<py::object>("jacobian"),
                                        reader.template get<py::object>("gamma")};
    reader.refuse_unread();
    const std::string what = "user_constraint '" + name + "'";
    std::array<std::shared_ptr<Callable<Space>>, 3> callables;
    for (int i = 0; i < 3; ++i)
      if (!functions[i].is_none())
        callables[i] = std::make_shared<Callable<Space>>(std::move(functions[i]),
                                                         static_cast<int>(bodies.size()), what);
    box.model.add(UserConstraintT<Space>(name, bodies, callables[0], callables[1], callables[2]));
  }

  /// A user force is compiled for one and for two bodies: the dict's body list picks.
  static void add_user_force(Box& box, const py::dict& values) {
    using Space = typename ModelType::Space;
    DictReader<ModelType> reader(box.model, values, UserForceT<Space, 1>::description);
    const auto name = parameter<std::string>(reader, "name");
    const auto bodies = reader.template get<std::vector<std::string>>("bodies");
    py::object function = reader.template get<py::object>("function");
    const bool differences =
        !values.contains("difference_jacobians") || parameter<bool>(reader, "difference_jacobians");
    py::object jacobians = reader.template get<py::object>("jacobians");
    reader.refuse_unread();
    const std::string what = "user_force '" + name + "'";
    if (bodies.size() != 1 && bodies.size() != 2)
      throw ModelError(what, "a user force acts on one or two bodies");
    const int count = static_cast<int>(bodies.size());
    auto callable = std::make_shared<Callable<Space>>(std::move(function), count, what);
    auto blocks = jacobians.is_none()
                      ? nullptr
                      : std::make_shared<Callable<Space>>(std::move(jacobians), count, what);
    if (count == 1)
      box.model.add(
          UserForceT<Space, 1>(name, {box.model.body(bodies[0])}, callable, differences, blocks));
    else
      box.model.add(UserForceT<Space, 2>(name,
                                         {box.model.body(bodies[0]), box.model.body(bodies[1])},
                                         callable, differences, blocks));
  }
};

/// Adds an element of type `type` to the box's model from the checked dict.
template <class Box>
void add_element(Box& box, const std::string& type, const py::dict& values) {
  if (box.running) throw ModelError("model", "cannot change a model while an analysis runs");
  const auto& adders = Catalogue<typename Box::ModelType>::adders();
  const auto found = adders.find(type);
  if (found == adders.end())
    throw ModelError(type, std::string("unknown ") + Box::space_name + " element type");
  box.assembled = {};  // the model changes: assemble again
  found->second(box, values);
}

}  // namespace odyn::python
