#pragma once
// Compliant contact between a sphere on body b and a plane or another sphere on body a (in the
// plane: a circle, and a line or a circle), and between a box or a capsule on b and a plane on
// a. A box touches at its corners and a capsule at its end spheres: a plane meets a convex
// solid deepest at one of those points, and each point past the plane pushes by the law below
// (as MuJoCo's box-plane and capsule-plane pairs do). Where the gap g between the surfaces is
// negative, the penetration delta = -g and its rate delta' give the Hunt-Crossley normal force
//   F_n = k delta^n (1 + d delta'),  kept >= 0 (no pull as the bodies separate),
// and the slip velocity v_t (the relative velocity of the contact point, across the normal) a
// regularized Coulomb friction
//   F_t = -mu F_n tanh(|v_t| / v_s) v_t / |v_t|,
// both acting on b at the contact point (the midpoint of the overlap) and opposite on a.
// A box or a capsule lying flat on the plane carries its weight on four or two points, and
// the forces add up.
//
// With no other force on the pair, an impact at speed v_in leaves at v_out with
//   d v_in - ln(1 + d v_in) = -d v_out - ln(1 - d v_out),
// whatever k and n (the first integral of m delta'' = -k delta^n (1 + d delta')): the restitution
// coefficient depends on d v_in only, falling from 1 at d v_in = 0 (Hunt and Crossley's
// d = 3 (1 - e) / (2 v_in) holds for e near 1 only).

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "odyn/core/description.hpp"
#include "odyn/core/element.hpp"
#include "odyn/core/errors.hpp"
#include "odyn/forces/hunt_crossley.hpp"

namespace odyn {

/// The contact laws' parameters: Hunt-Crossley normal force, regularized Coulomb friction.
struct ContactLaw {
  double stiffness = 0.0;    // k, N/m^n
  double exponent = 1.5;     // n (3/2: Hertz, for spheres)
  double dissipation = 0.0;  // d, s/m
  double friction = 0.0;     // mu
  double slip_speed = 1e-3;  // v_s, m/s: the slip at which friction reaches tanh(1) mu F_n

  /// The normal law.
  HuntCrossley normal_law() const { return {stiffness, exponent, dissipation}; }
  /// The normal force at penetration `depth` (> 0) and its rate.
  double normal_force(double depth, double rate) const {
    return normal_law().at(depth, rate).force;
  }
  /// The elastic energy stored at penetration `depth` (> 0).
  double energy(double depth) const { return normal_law().energy(depth); }
  /// mu tanh(s / v_s) / s: the friction force per unit normal force and unit slip velocity.
  double friction_per_slip(double slip) const {
    if (friction == 0.0) return 0.0;
    const double x = slip / slip_speed;
    return friction * (x > 1e-8 ? std::tanh(x) / slip : 1.0 / slip_speed);
  }
};

namespace parameters {
inline constexpr std::array<Parameter, 5> contact_law{{
    {"stiffness", "positive", nullptr, "N/m^n", "k: the normal force is k delta^n at rest"},
    {"exponent", "positive", "1.5", "", "n >= 1 (1.5: Hertz's, for spheres)"},
    {"dissipation", "nonnegative", "0", "s/m",
     "d: the normal force is k delta^n (1 + d delta'); for a restitution e at an impact speed "
     "v, odyn.hunt_crossley_dissipation(e, v)"},
    {"friction", "nonnegative", "0", "", "mu, the Coulomb friction coefficient"},
    {"slip_speed", "positive", "0.001", "m/s",
     "v_s: the friction force is mu F_n tanh(|v_t| / v_s)"},
}};
}  // namespace parameters

/// The shapes a sphere on body b touches: a plane (a line in the plane) or a sphere on body a.
namespace contact_shape {

template <class Space>
struct Plane {
  typename Space::Vector point, normal;  // on body a, in a's coordinates; normal unit, outward

  static constexpr const char* type = Space::dim == 3 ? "sphere_plane" : "circle_line";
  static constexpr std::array<Parameter, 2> parameter_list{{
      {"point", "vector", "0", "m", "a point of the plane (line) on body a, in a's coordinates"},
      {"normal", "vector", Space::dim == 3 ? "[0, 0, 1]" : "[0, 1]", "",
       "the plane's (line's) outward normal, in a's coordinates; b's side of a"},
  }};
  static constexpr const char* summary =
      Space::dim == 3
          ? "Compliant contact of a sphere on b with a plane on a (the half-space behind the "
            "normal is solid): Hunt-Crossley normal force k delta^n (1 + d delta'), regularized "
            "Coulomb friction."
          : "Compliant contact of a circle on b with a line on a (the half-plane behind the "
            "normal is solid): Hunt-Crossley normal force k delta^n (1 + d delta'), regularized "
            "Coulomb friction.";
  template <class Reader>
  static Plane read(Reader& r) {
    return {parameter<typename Space::Vector>(r, "point"),
            parameter<typename Space::Vector>(r, "normal")};
  }
  void check(const std::string& name) {
    if (!point.allFinite() || !normal.allFinite())
      throw ModelError(name, "the plane's point and normal must be finite");
    const double length = normal.norm();
    if (!(length > 1e-12))
      throw ModelError(name, "the normal is zero; give the plane's outward direction on body a");
    normal /= length;
  }
  /// The outward unit normal (towards b's sphere at `center`) and the signed distance of that
  /// centre from the surface.
  template <class Frame>
  std::pair<typename Space::Vector, double> towards(const Frame& a,
                                                    const typename Space::Vector& center) const {
    const typename Space::Vector n = a.direction(normal);
    return {n, n.dot(center - a.point(point))};
  }
};

template <class Space>
struct Sphere {
  typename Space::Vector center;  // on body a, in a's coordinates
  double radius = 0.0;

  static constexpr const char* type = Space::dim == 3 ? "sphere_sphere" : "circle_circle";
  static constexpr std::array<Parameter, 2> parameter_list{{
      {"radius_a", "positive", nullptr, "m", "the radius of a's sphere (circle)"},
      {"center_a", "vector", "0", "m", "the centre of a's sphere (circle), in a's coordinates"},
  }};
  static constexpr const char* summary =
      Space::dim == 3 ? "Compliant contact of a sphere on b with a sphere on a: Hunt-Crossley "
                        "normal force k delta^n (1 + d delta'), regularized Coulomb friction."
                      : "Compliant contact of a circle on b with a circle on a: Hunt-Crossley "
                        "normal force k delta^n (1 + d delta'), regularized Coulomb friction.";
  template <class Reader>
  static Sphere read(Reader& r) {
    return {parameter<typename Space::Vector>(r, "center_a"), parameter<double>(r, "radius_a")};
  }
  void check(const std::string& name) const {
    if (!center.allFinite()) throw ModelError(name, "the centre on body a must be finite");
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw ModelError(name, "radius_a is " + to_text(radius) + "; it must be positive");
  }
  template <class Frame>
  std::pair<typename Space::Vector, double> towards(const Frame& a,
                                                    const typename Space::Vector& center) const {
    const typename Space::Vector d = center - a.point(this->center);
    const double length = d.norm();
    // Concentric spheres: any direction is as good; a's first axis keeps the force finite.
    const typename Space::Vector n =
        length > 0.0 ? typename Space::Vector(d / length) : a.direction(Space::Vector::Unit(0));
    return {n, length - radius};
  }
};

/// A sphere (circle) on body b: one point of contact, its centre.
template <class Space>
struct Ball {
  using Vector = typename Space::Vector;
  Vector center = Vector::Zero();  // in b's coordinates
  double radius = 0.0;

  static constexpr int count = 1;
  static constexpr bool names_the_pair = false;  // sphere_plane, sphere_sphere: a's shape names it
  static constexpr std::array<Parameter, 2> parameter_list{{
      {"radius_b", "positive", nullptr, "m", "the radius of b's sphere (circle)"},
      {"center_b", "vector", "0", "m", "the centre of b's sphere (circle), in b's coordinates"},
  }};
  template <class Reader>
  static Ball read(Reader& r) {
    return {parameter<Vector>(r, "center_b"), parameter<double>(r, "radius_b")};
  }
  void check(const std::string& name) const {
    if (!center.allFinite()) throw ModelError(name, "the centre on body b must be finite");
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw ModelError(name, "radius_b is " + to_text(radius) + "; it must be positive");
  }
  std::array<Vector, count> centers() const { return {center}; }
};

/// A box (rectangle) on body b, its edges along b's axes: it touches a plane at its corners.
template <class Space>
struct Box {
  using Vector = typename Space::Vector;
  Vector center = Vector::Zero(), half_extents = Vector::Zero();  // in b's coordinates
  static constexpr double radius = 0.0;

  static constexpr int count = Space::dim == 3 ? 8 : 4;
  static constexpr bool names_the_pair = true;
  static constexpr const char* type = Space::dim == 3 ? "box_plane" : "rectangle_line";
  static constexpr const char* summary =
      Space::dim == 3
          ? "Compliant contact of a box on b with a plane on a, at the box's corners: "
            "Hunt-Crossley normal force k delta^n (1 + d delta') and regularized Coulomb friction "
            "at each corner inside the plane."
          : "Compliant contact of a rectangle on b with a line on a, at the rectangle's corners: "
            "Hunt-Crossley normal force k delta^n (1 + d delta') and regularized Coulomb friction "
            "at each corner inside the line.";
  static constexpr std::array<Parameter, 2> parameter_list{{
      {"half_extents", "vector", nullptr, "m",
       "half the box's (rectangle's) edge lengths along b's axes"},
      {"center_b", "vector", "0", "m", "the box's (rectangle's) centre, in b's coordinates"},
  }};
  template <class Reader>
  static Box read(Reader& r) {
    return {parameter<Vector>(r, "center_b"), parameter<Vector>(r, "half_extents")};
  }
  void check(const std::string& name) const {
    if (!center.allFinite()) throw ModelError(name, "the centre on body b must be finite");
    if (!half_extents.allFinite() || !(half_extents.minCoeff() > 0.0))
      throw ModelError(name, "half_extents is (" + to_text(half_extents.transpose()) +
                                 "); each half edge length must be positive");
  }
  std::array<Vector, count> centers() const {
    std::array<Vector, count> corners;
    for (int corner = 0; corner < count; ++corner)
      for (int axis = 0; axis < Space::dim; ++axis)
        corners[corner][axis] =
            center[axis] + ((corner >> axis) & 1 ? half_extents[axis] : -half_extents[axis]);
    return corners;
  }
};

/// A capsule on body b (a cylinder with hemispherical ends; in the plane, a stadium): it
/// touches a plane at its end spheres.
template <class Space>
struct Capsule {
  using Vector = typename Space::Vector;
  Vector center = Vector::Zero(), axis = Vector::Unit(Space::dim == 3 ? 2 : 0);  // in b's axes
  double half_length = 0.0, radius = 0.0;

  static constexpr int count = 2;
  static constexpr bool names_the_pair = true;
  static constexpr const char* type = Space::dim == 3 ? "capsule_plane" : "capsule_line";
  static constexpr const char* summary =
      Space::dim == 3
          ? "Compliant contact of a capsule on b with a plane on a, at its end spheres: "
            "Hunt-Crossley normal force k delta^n (1 + d delta') and regularized Coulomb friction "
            "at each end inside the plane."
          : "Compliant contact of a capsule (a stadium) on b with a line on a, at its end "
            "circles: Hunt-Crossley normal force k delta^n (1 + d delta') and regularized "
            "Coulomb friction at each end inside the line.";
  static constexpr std::array<Parameter, 4> parameter_list{{
      {"radius_b", "positive", nullptr, "m", "the capsule's radius"},
      {"half_length", "positive", nullptr, "m",
       "half the distance between the end spheres' (circles') centres"},
      {"axis_b", "vector", Space::dim == 3 ? "[0, 0, 1]" : "[1, 0]", "",
       "the capsule's axis, in b's coordinates"},
      {"center_b", "vector", "0", "m", "the capsule's centre, in b's coordinates"},
  }};
  template <class Reader>
  static Capsule read(Reader& r) {
    return {parameter<Vector>(r, "center_b"), parameter<Vector>(r, "axis_b"),
            parameter<double>(r, "half_length"), parameter<double>(r, "radius_b")};
  }
  void check(const std::string& name) {
    if (!center.allFinite()) throw ModelError(name, "the centre on body b must be finite");
    const double length = axis.norm();
    if (!axis.allFinite() || !(length > 1e-12))
      throw ModelError(
          name, "axis_b is (" + to_text(axis.transpose()) + "); give the capsule's direction");
    axis /= length;
    if (!(half_length > 0.0) || !std::isfinite(half_length))
      throw ModelError(name,
                       "half_length is " + to_text(half_length) +
                           "; it must be positive (for a sphere, use sphere_plane or circle_line)");
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw ModelError(name, "radius_b is " + to_text(radius) + "; it must be positive");
  }
  std::array<Vector, count> centers() const {
    return {Vector(center - half_length * axis), Vector(center + half_length * axis)};
  }
};

}  // namespace contact_shape

/// The outputs of a contact touching at `count` points: a sphere's, and for a box or a
/// capsule how many of its points touch.
template <int count>
constexpr auto contact_outputs() {
  constexpr std::array<Output, 5> sphere{{
      {"gap", "m", "the distance between the surfaces; negative while they overlap"},
      {"gap_rate", "m/s", "the gap's rate, positive as the surfaces separate"},
      {"normal_force", "N", "F_n, pushing b away from a"},
      {"slip", "m/s", "|v_t|, the contact point's slip speed"},
      {"friction_force", "N", "|F_t|, the friction force's magnitude"},
  }};
  if constexpr (count == 1) {
    return sphere;
  } else {
    return std::array<Output, 6>{{
        {"gap", "m", "the smallest distance from b's corners (end spheres) to the plane"},
        {"gap_rate", "m/s", "that point's gap rate, positive as it leaves"},
        {"normal_force", "N", "the normal forces' sum, pushing b away from a"},
        {"slip", "m/s", "the slip speed at that point"},
        {"friction_force", "N", "the sum of the friction forces' magnitudes"},
        {"points", "", "how many corners (end spheres) touch"},
    }};
  }
}

/// A contact's type name and summary: a sphere's come from a's shape (sphere_plane,
/// sphere_sphere), a box's or a capsule's from the solid (box_plane, capsule_plane).
template <class Shape, class Solid>
constexpr std::array<const char*, 2> contact_names() {
  if constexpr (Solid::names_the_pair)
    return {Solid::type, Solid::summary};
  else
    return {Shape::type, Shape::summary};
}

/// A Solid on body b (a sphere, a box or a capsule) against a Shape on body a; see the top of
/// this header.
template <class SpaceT, template <class> class ShapeT,
          template <class> class SolidT = contact_shape::Ball>
class ContactT {
 public:
  using Space = SpaceT;
  using Vector = typename Space::Vector;
  using Frame = typename Space::Frame;
  using Shape = ShapeT<Space>;
  using Solid = SolidT<Space>;
  static constexpr int num_bodies = 2;
  using Input = ElementInput<Space, 2>;

  static constexpr std::array<Parameter, 3> pair{{
      {"name", "name", nullptr, "", "the element's name"},
      {"body_a", "body", nullptr, "", "the body with the plane or the first sphere"},
      {"body_b", "body", nullptr, "",
       Solid::names_the_pair ? "the body with the solid" : "the body with the sphere"},
  }};
  static constexpr auto parameter_list =
      join(join(join(pair, Solid::parameter_list), Shape::parameter_list), parameters::contact_law);
  static constexpr auto output_list = contact_outputs<Solid::count>();
  static constexpr ElementDescription description{contact_names<Shape, Solid>()[0], "force",
                                                  contact_names<Shape, Solid>()[1], parameter_list,
                                                  output_list};
  template <class Reader>
  static ContactT from_parameters(Reader& r) {
    const auto name = parameter<std::string>(r, "name");
    const BodyId a = parameter<BodyId>(r, "body_a"), b = parameter<BodyId>(r, "body_b");
    Solid solid = Solid::read(r);
    const Shape shape = Shape::read(r);
    const ContactLaw law{parameter<double>(r, "stiffness"), parameter<double>(r, "exponent"),
                         parameter<double>(r, "dissipation"), parameter<double>(r, "friction"),
                         parameter<double>(r, "slip_speed")};
    return ContactT(name, a, shape, b, std::move(solid), law);
  }

  ContactT(std::string name, BodyId body_a, Shape shape, BodyId body_b, Solid solid, ContactLaw law)
      : name_(std::move(name)),
        bodies_{body_a, body_b},
        shape_(std::move(shape)),
        solid_(std::move(solid)),
        law_(law) {
    shape_.check(name_);
    solid_.check(name_);
    centers_ = solid_.centers();
    law_.normal_law().check(name_);
    if (!(law_.friction >= 0.0) || !std::isfinite(law_.friction))
      throw ModelError(name_,
                       "friction is " + to_text(law_.friction) + "; it must be zero or positive");
    if (!(law_.slip_speed > 0.0) || !std::isfinite(law_.slip_speed))
      throw ModelError(name_,
                       "slip_speed is " + to_text(law_.slip_speed) + "; it must be positive");
    if (bodies_[0] == bodies_[1])
      throw ModelError(name_, "body_a and body_b are the same body; contact acts between two");
  }
  /// A sphere of `radius_b` centred at `center_b` on b.
  ContactT(std::string name, BodyId body_a, Shape shape, BodyId body_b, const Vector& center_b,
           double radius_b, ContactLaw law)
    requires(!Solid::names_the_pair)
      : ContactT(std::move(name), body_a, std::move(shape), body_b, Solid{center_b, radius_b},
                 law) {}

  const std::string& name() const { return name_; }
  const std::array<BodyId, 2>& bodies() const { return bodies_; }
  const ContactLaw& law() const { return law_; }
  /// The points of b that touch (a sphere's centre, a box's corners, a capsule's end centres),
  /// in b's coordinates, each the centre of a sphere of radius solid().radius.
  const std::array<Vector, Solid::count>& points() const { return centers_; }

  void evaluate(const Input& in, ForceBlocks<Space, 2>& out) const {
    out.force[0].setZero();
    out.force[1].setZero();
    for (const Vector& center : centers_) {
      const Touch c = touch(in, center);
      if (c.gap >= 0.0) continue;
      const Vector force = force_on_b(c);
      out.force[0] -= c.jacobian_a.transpose() * force;
      out.force[1] += c.jacobian_b.transpose() * force;
    }
  }

  /// Newton-matrix blocks, summed over the touching points: the normal law's stiffness and
  /// damping, which move the friction with the normal force, and the friction's damping across
  /// the normal (the lever arms' and the normal's own change left out, as a Tsda leaves them).
  /// The friction's block is its secant mu F_n tanh(s / v_s) / s rather than its tangent: on
  /// tanh's flat shoulders the tangent is near zero, and Newton's iteration would swing from
  /// one side of the stick region to the other instead of settling in it.
  void jacobians(const Input& in, ForceBlocks<Space, 2>& out) const {
    out.stiffness.setZero();
    out.damping.setZero();
    for (const Vector& center : centers_) {
      const Touch c = touch(in, center);
      if (c.gap >= 0.0) continue;
      const double depth = -c.gap, rate = -c.gap_rate;
      const auto [normal, stiffness, damping] = law_.normal_law().at(depth, rate);
      if (normal <= 0.0) continue;  // separating faster than the law pushes: no force near here
      const double per_slip = law_.friction_per_slip(c.slip.norm());
      // The force on b per unit normal force, friction included: F = F_n (n - phi v_t).
      const Vector per_normal = c.normal - per_slip * c.slip;
      using Square = Eigen::Matrix<double, Space::dim, Space::dim>;
      const Square across = Square::Identity() - c.normal * c.normal.transpose();
      Eigen::Matrix<double, Space::dim, 2 * Space::nv> relative;  // d(v_b - v_a at the point)/dv
      relative << -c.jacobian_a, c.jacobian_b;
      const Eigen::Matrix<double, 1, 2 * Space::nv> along = c.normal.transpose() * relative;
      out.stiffness += (relative.transpose() * (stiffness * per_normal)) * along;
      out.damping += (relative.transpose() * (damping * per_normal)) * along +
                     relative.transpose() * ((normal * per_slip) * across) * relative;
    }
  }

  double potential_energy(const Input& in) const {
    double energy = 0.0;
    for (const Vector& center : centers_) {
      const double gap = touch(in, center).gap;
      if (gap < 0.0) energy += law_.energy(-gap);
    }
    return energy;
  }

  auto outputs(const Input& in) const {
    double gap = std::numeric_limits<double>::infinity(), gap_rate = 0.0, slip = 0.0;
    double normal = 0.0, friction = 0.0;
    int touching = 0;
    for (const Vector& center : centers_) {
      const Touch c = touch(in, center);
      if (c.gap < gap) {
        gap = c.gap;
        gap_rate = c.gap_rate;
        slip = c.slip.norm();
      }
      if (c.gap >= 0.0) continue;
      const double push = law_.normal_force(-c.gap, -c.gap_rate);
      normal += push;
      friction += push * law_.friction_per_slip(c.slip.norm()) * c.slip.norm();
      touching += push > 0.0;
    }
    if constexpr (Solid::count == 1)
      return std::array<double, 5>{gap, gap_rate, normal, slip, friction};
    else
      return std::array<double, 6>{gap, gap_rate, normal, slip, friction, double(touching)};
  }

 private:
  struct Touch {
    Vector normal;  // unit, from a towards b
    double gap = 0.0, gap_rate = 0.0;
    Vector slip;  // the contact point's relative velocity across the normal
    typename Space::PointJacobian jacobian_a, jacobian_b;  // at the contact point
  };

  /// The sphere of b's solid centred at `center_b` (in b's coordinates) against a's shape.
  Touch touch(const Input& in, const Vector& center_b) const {
    const Frame &a = in.body(0), &b = in.body(1);
    const Vector center = b.point(center_b);
    const auto [normal, distance] = shape_.towards(a, center);
    Touch c;
    c.normal = normal;
    c.gap = distance - solid_.radius;
    // The midpoint of the overlap (of the gap while apart), as a body-fixed point of each body.
    const Vector point = center - (solid_.radius + 0.5 * c.gap) * normal;
    const Vector on_a = a.rotation.transpose() * (point - a.position);
    const Vector on_b = b.rotation.transpose() * (point - b.position);
    const Vector relative = b.point_velocity(on_b) - a.point_velocity(on_a);
    c.gap_rate = normal.dot(relative);
    c.slip = relative - c.gap_rate * normal;
    c.jacobian_a = a.point_jacobian(on_a);
    c.jacobian_b = b.point_jacobian(on_b);
    return c;
  }

  /// The force on b at the contact point (the touch has gap < 0).
  Vector force_on_b(const Touch& c) const {
    const double normal = law_.normal_force(-c.gap, -c.gap_rate);
    return normal * c.normal - (normal * law_.friction_per_slip(c.slip.norm())) * c.slip;
  }

  std::string name_;
  std::array<BodyId, 2> bodies_;
  Shape shape_;
  Solid solid_;
  std::array<Vector, Solid::count> centers_;
  ContactLaw law_;
};

template <class Space>
using SpherePlaneT = ContactT<Space, contact_shape::Plane>;
template <class Space>
using SphereSphereT = ContactT<Space, contact_shape::Sphere>;
template <class Space>
using BoxPlaneT = ContactT<Space, contact_shape::Plane, contact_shape::Box>;
template <class Space>
using CapsulePlaneT = ContactT<Space, contact_shape::Plane, contact_shape::Capsule>;

}  // namespace odyn
