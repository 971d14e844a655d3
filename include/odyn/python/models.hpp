#pragma once
// The model types a Python module compiles: every element of the library's catalogue, the
// elements written in Python, and any further element types of the module's own (a downstream
// module's, or an example's), then the box a Python model object holds.

#include <memory>
#include <type_traits>

#include <odyn/odyn.hpp>
#include <odyn/python/run_monitor.hpp>
#include <odyn/python/user_elements.hpp>

namespace odyn::python {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;

/// The spatial model type of a Python module: the library's elements, then `Extra` (the
/// module's own element types, each describing itself: odyn/core/description.hpp), then the
/// elements written in Python. Every element type in it can be added from Python (catalogue.hpp).
template <class... Extra>
using SpatialModelWith =
    sp::Model<sp::Revolute, sp::Translational, sp::Spherical, sp::Universal, sp::CvJoint,
              sp::Cylindrical, sp::Fixed, sp::Distance, sp::PlanarJoint, sp::InLine, sp::InPlane,
              sp::Orientation, sp::ParallelAxes, sp::Perpendicular, sp::Gear, sp::RackPinion,
              sp::Coupler, sp::ScrewJoint, sp::RevoluteDriver, sp::TranslationalDriver, sp::Gravity,
              sp::PointForce, sp::PointTorque, sp::Tsda, sp::Rsda, sp::Bushing, sp::SpherePlane,
              sp::SphereSphere, sp::BoxPlane, sp::CapsulePlane, sp::RevoluteLimit,
              sp::TranslationalLimit, sp::JointFriction, Extra..., UserForceT<Spatial, 1>,
              UserForceT<Spatial, 2>, UserConstraintT<Spatial>, SignalWatch<Spatial>>;

/// The planar model type of a Python module, as SpatialModelWith.
template <class... Extra>
using PlanarModelWith =
    pl::Model<pl::Revolute, pl::Translational, pl::Fixed, pl::Distance, pl::InLine, pl::Gear,
              pl::RackPinion, pl::Coupler, pl::RevoluteDriver, pl::TranslationalDriver, pl::Gravity,
              pl::PointForce, pl::PointTorque, pl::Tsda, pl::Rsda, pl::Bushing, pl::CircleLine,
              pl::CircleCircle, pl::RectangleLine, pl::CapsuleLine, pl::RevoluteLimit,
              pl::TranslationalLimit, pl::JointFriction, Extra..., UserForceT<Planar, 1>,
              UserForceT<Planar, 2>, UserConstraintT<Planar>, SignalWatch<Planar>>;

/// A model type of just `Elements` and the elements written in Python (and the signal watch every
/// model of a module holds): a module that compiles only what its models need builds in a
/// fraction of the time.
template <class... Elements>
using SpatialModelOf = sp::Model<Elements..., UserForceT<Spatial, 1>, UserForceT<Spatial, 2>,
                                 UserConstraintT<Spatial>, SignalWatch<Spatial>>;
template <class... Elements>
using PlanarModelOf = pl::Model<Elements..., UserForceT<Planar, 1>, UserForceT<Planar, 2>,
                                UserConstraintT<Planar>, SignalWatch<Planar>>;

/// True if `Target` compiles every element type of the library's catalogue `Catalogue` (its
/// DefaultModel): a new element in the library fails this check until the lists above have it.
template <class Target, class Catalogue>
struct CoversCatalogue;
template <class Target, class Body, class... Elements>
struct CoversCatalogue<Target, odyn::Model<Body, Elements...>> {
  static constexpr bool value = (Target::template holds<Elements> && ...);
};
static_assert(CoversCatalogue<SpatialModelWith<>, sp::DefaultModel>::value,
              "SpatialModelWith lacks an element of odyn::spatial::DefaultModel");
static_assert(CoversCatalogue<PlanarModelWith<>, pl::DefaultModel>::value,
              "PlanarModelWith lacks an element of odyn::planar::DefaultModel");

/// The model a Python odyn.Model (or odyn.PlanarModel) holds, and whether an analysis is
/// running on it (while the GIL is released, another thread must not change it).
template <class M>
struct ModelBox {
  using ModelType = M;
  using Space = typename M::Space;
  static constexpr const char* space_name = std::is_same_v<Space, Planar> ? "planar" : "spatial";
  ModelBox() { model.add(SignalWatch<Space>(monitor)); }
  std::shared_ptr<RunMonitor> monitor = std::make_shared<RunMonitor>();
  M model;
  bool running = false;
  /// The last assembly's state, until the model changes: runs start from it (see
  /// AssembledStart), so that `simulate` after `assemble` does not assemble again.
  AssembledStart<M> assembled;
};

}  // namespace odyn::python
