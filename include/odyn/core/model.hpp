#pragma once
// The model: bodies and elements with their parameters. It never changes during a run; every
// buffer an analysis writes lives in a Workspace (the model/workspace split).
//
// Model<Body, Elements...> lists at compile time the body type (which fixes the block sizes)
// and the element types a scene uses; each element type gets a contiguous pool, so hot loops
// run over type-homogeneous arrays with no per-element dispatch.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/core/ids.hpp"

namespace odyn {

namespace detail {
template <class T, class... Ts>
constexpr std::size_t index_of() {
  constexpr std::array<bool, sizeof...(Ts)> same{std::is_same_v<T, Ts>...};
  for (std::size_t i = 0; i < same.size(); ++i)
    if (same[i]) return i;
  return sizeof...(Ts);
}
}  // namespace detail

template <class BodyT, Element... Elements>
class Model {
 public:
  using Body = BodyT;
  using Space = typename Body::Space;
  using Frame = typename Space::Frame;
  using Variant = std::variant<Elements...>;
  static constexpr int nq = Space::nq;
  static constexpr int nv = Space::nv;
  static constexpr std::size_t num_types = sizeof...(Elements);

  template <class E>
  static constexpr std::size_t type_index = detail::index_of<E, Elements...>();
  template <class E>
  static constexpr bool holds = type_index<E> < num_types;

  /// Where an element is: its type's position in the list and its index in that pool.
  struct Location {
    std::size_t type;
    std::size_t index;
  };

  /// Where a body lacks inertia (a point mass, a slender rod): Body's MasslessDirections.
  using Massless = decltype(std::declval<const Body&>().massless());

  Model() {
    Body ground_body;
    ground_body.name = "ground";
    bodies_.push_back(ground_body);
    massless_.emplace_back();
    body_names_.emplace("ground", 0);
  }

  /// Adds a moving body; throws ModelError if it is not physical or its name is taken. A point
  /// mass or a slender rod is kept with a stand-in moment where it has none (see massless).
  BodyId add_body(Body body) {
    body.validate();
    claim_name(body.name);
    const Massless massless = body.massless();
    body.inertia = massless.filled(body.inertia);
    has_massless_bodies_ = has_massless_bodies_ || massless.count > 0;
    massless_.push_back(massless);
    body_names_.emplace(body.name, static_cast<int>(bodies_.size()));
    bodies_.push_back(std::move(body));
    return BodyId{static_cast<int>(bodies_.size()) - 1};
  }

  /// Adds an element; throws ModelError naming it if it refers to unknown or repeated bodies.
  template <class E>
  requires holds<E> Handle<E> add(E element) {
    claim_name(element.name());
    if constexpr (OnJoint<E>) attach_to_joint(element);
    if constexpr (!FieldForce<E>) {
      check_bodies(element.name(), element.bodies());
      if constexpr (BindsToInitialPose<E>) {
        std::array<Frame, E::num_bodies> frames;
        InputOf<E> in;
        for (int i = 0; i < E::num_bodies; ++i) {
          frames[i] = initial_frame(element.bodies()[i]);
          in.frames[i] = &frames[i];
        }
        element.bind(in);
      }
    }
    auto& pool = std::get<type_index<E>>(pools_);
    auto& rows = row_offsets_[type_index<E>];
    if constexpr (Constraint<E>) {
      rows.push_back(num_equations_);
      num_equations_ += E::num_equations;
    }
    element_names_.emplace(element.name(), Location{type_index<E>, pool.size()});
    pool.push_back(std::move(element));
    return Handle<E>{pool.size() - 1};
  }

  /// Adds an element given as a variant (the front door for scripting).
  void add(const Variant& element) {
    std::visit([this](const auto& e) { add(e); }, element);
  }

  // --- bodies --------------------------------------------------------------------------
  int num_bodies() const { return static_cast<int>(bodies_.size()) - 1; }  // moving ones
  /// The body as the equations of motion take it: a point mass's or a slender rod's inertia has
  /// the stand-in moment where it has none (massless says where).
  const Body& body(BodyId id) const { return bodies_.at(id.index); }
  const Massless& massless(BodyId id) const { return massless_.at(id.index); }
  /// True if some body is a point mass or a slender rod.
  bool has_massless_bodies() const { return has_massless_bodies_; }
  BodyId body(std::string_view name) const {
    const auto it = body_names_.find(std::string(name));
    if (it == body_names_.end())
      throw ModelError(std::string(name), "no body of that name in the model");
    return BodyId{it->second};
  }
  /// Offset of a body's block in configuration (nq) and velocity (nv) vectors; -1 for ground.
  static int configuration_offset(BodyId id) { return (id.index - 1) * nq; }
  static int velocity_offset(BodyId id) { return (id.index - 1) * nv; }

  int num_coordinates() const { return nq * num_bodies(); }
  int num_velocities() const { return nv * num_bodies(); }
  int num_equations() const { return num_equations_; }

  Eigen::VectorXd initial_configuration() const {
    Eigen::VectorXd q(num_coordinates());
    for (int b = 1; b <= num_bodies(); ++b)
      q.segment<nq>((b - 1) * nq) = bodies_[b].configuration();
    return q;
  }
  Eigen::VectorXd initial_velocity() const {
    Eigen::VectorXd v(num_velocities());
    for (int b = 1; b <= num_bodies(); ++b) v.segment<nv>((b - 1) * nv) = bodies_[b].velocity();
    return v;
  }

  // --- elements ------------------------------------------------------------------------
  template <class E>
  const std::vector<E>& pool() const {
    return std::get<type_index<E>>(pools_);
  }
  template <class E>
  const E& element(Handle<E> handle) const {
    return pool<E>().at(handle.index);
  }
  /// First constraint row of a constraint element.
  template <class E>
  int row(Handle<E> handle) const {
    return row_offsets_[type_index<E>].at(handle.index);
  }
  template <class E>
  const std::vector<int>& rows() const {
    return row_offsets_[type_index<E>];
  }
  Location locate(std::string_view name) const {
    const auto it = element_names_.find(std::string(name));
    if (it == element_names_.end())
      throw ModelError(std::string(name), "no element of that name in the model");
    return it->second;
  }
  /// A handle to the element `name`, which must be of type E.
  template <class E>
  Handle<E> handle(std::string_view name) const {
    const Location where = locate(name);
    if (where.type != type_index<E>)
      throw ModelError(std::string(name), "the element is of another type than requested");
    return Handle<E>{where.index};
  }

  /// Calls f(pool, type_index_constant) for every element type, in the order of the list.
  template <class F>
  void for_each_pool(F&& f) const {
    for_each_pool_impl(f, std::make_index_sequence<num_types>{});
  }

  /// Name of the element that owns constraint row `row`.
  std::string constraint_name(int row) const {
    std::string found;
    for_each_pool([&]<class E>(const std::vector<E>& pool, auto type) {
      if constexpr (Constraint<E>) {
        const auto& offsets = row_offsets_[type];
        for (std::size_t i = 0; i < pool.size(); ++i)
          if (row >= offsets[i] && row < offsets[i] + E::num_equations) found = pool[i].name();
      }
    });
    return found;
  }

  /// The frame of a body at its initial pose and velocity (identity for the ground).
  Frame initial_frame(BodyId id) const {
    Frame frame;
    if (!id.is_ground())
      Space::make_frame(bodies_[id.index].configuration(), bodies_[id.index].velocity(), frame);
    return frame;
  }

 private:
  template <class F, std::size_t... I>
  void for_each_pool_impl(F& f, std::index_sequence<I...>) const {
    (f(std::get<I>(pools_), std::integral_constant<std::size_t, I>{}), ...);
  }

  void claim_name(const std::string& name) {
    if (name.empty()) throw ModelError("(unnamed)", "every body and element needs a name");
    if (body_names_.count(name) || element_names_.count(name))
      throw ModelError(name, "the name is already used in this model; names must be unique");
  }

  /// Gives an element that sits on a joint (OnJoint) that joint and its place in the model.
  template <class E>
  void attach_to_joint(E& element) const {
    const std::string joint = element.joint_name();
    const auto it = element_names_.find(joint);
    if (it == element_names_.end())
      throw ModelError(element.name(), "no joint named '" + joint +
                                           "' in the model; add the joint before the elements "
                                           "that sit on it");
    bool attached = false;
    for_each_pool([&]<class J>(const std::vector<J>& pool, auto type) {
      if constexpr (requires { element.attach(pool.front(), type, it->second.index); }) {
        if (type != it->second.type) return;
        element.attach(pool[it->second.index], type, it->second.index);
        attached = true;
      }
    });
    if (!attached)
      throw ModelError(element.name(), "'" + joint + "' is not a joint this element can sit on");
  }

  template <std::size_t N>
  void check_bodies(const std::string& name, const std::array<BodyId, N>& ids) const {
    for (const BodyId id : ids)
      if (id.index < 0 || id.index >= static_cast<int>(bodies_.size()))
        throw ModelError(name, "refers to body number " + std::to_string(id.index) +
                                   ", which is not in the model (it has " +
                                   std::to_string(num_bodies()) + " moving bodies)");
    if constexpr (N == 2)
      if (ids[0] == ids[1])
        throw ModelError(name, "connects body '" + bodies_[ids[0].index].name +
                                   "' to itself; a joint needs two different bodies");
  }

  std::vector<Body> bodies_;
  std::vector<Massless> massless_;
  bool has_massless_bodies_ = false;
  std::tuple<std::vector<Elements>...> pools_;
  std::array<std::vector<int>, num_types> row_offsets_;
  std::unordered_map<std::string, int> body_names_;
  std::unordered_map<std::string, Location> element_names_;
  int num_equations_ = 0;
};

}  // namespace odyn
