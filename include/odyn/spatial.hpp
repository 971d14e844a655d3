#pragma once
// The spatial element catalogue and the model types built from it.

#include "odyn/core/coupler.hpp"
#include "odyn/core/model.hpp"
#include "odyn/forces/contact.hpp"
#include "odyn/forces/gravity.hpp"
#include "odyn/forces/joint_friction.hpp"
#include "odyn/forces/point_load.hpp"
#include "odyn/forces/tsda.hpp"
#include "odyn/spatial/body.hpp"
#include "odyn/spatial/bushing.hpp"
#include "odyn/spatial/composite.hpp"
#include "odyn/spatial/cv_joint.hpp"
#include "odyn/spatial/cylindrical.hpp"
#include "odyn/spatial/distance.hpp"
#include "odyn/spatial/drivers.hpp"
#include "odyn/spatial/fixed.hpp"
#include "odyn/spatial/joint_primitives.hpp"
#include "odyn/spatial/limits.hpp"
#include "odyn/spatial/revolute.hpp"
#include "odyn/spatial/rsda.hpp"
#include "odyn/spatial/screw_joint.hpp"
#include "odyn/spatial/spherical.hpp"
#include "odyn/spatial/translational.hpp"
#include "odyn/spatial/universal.hpp"

namespace odyn::spatial {

using Gravity = GravityField<Spatial>;
using PointForce = PointForceT<Spatial>;
using PointTorque = PointTorqueT<Spatial>;
using Tsda = TsdaT<Spatial>;
using SpherePlane = SpherePlaneT<Spatial>;
using SphereSphere = SphereSphereT<Spatial>;
using BoxPlane = BoxPlaneT<Spatial>;
using CapsulePlane = CapsulePlaneT<Spatial>;
using Gear = GearT<PairJoint, JointFrame>;
using RackPinion = RackPinionT<PairJoint, JointFrame>;
using Coupler = CouplerT<PairJoint, JointFrame>;
using JointFriction = JointFrictionT<PairJoint>;

/// The joint types a turning_joint (its angle), a sliding_joint (its slide) or a coupled_joint
/// (either) parameter names.
inline constexpr auto turning_joint_types = parameters::turning_joints;
inline constexpr auto sliding_joint_types = parameters::sliding_joints;
inline constexpr auto coupled_joint_types = parameters::coupled_joints;

/// A spatial model holding just the element types a scene lists.
template <class... Elements>
using Model = odyn::Model<Body, Elements...>;

/// Every spatial element type of the library (what scripting uses).
using DefaultModel =
    Model<Revolute, Translational, Spherical, Universal, CvJoint, Cylindrical, Fixed, Distance,
          PlanarJoint, InLine, InPlane, Orientation, ParallelAxes, Perpendicular, Gear, RackPinion,
          Coupler, ScrewJoint, RevoluteDriver, TranslationalDriver, Gravity, PointForce,
          PointTorque, Tsda, Rsda, Bushing, SpherePlane, SphereSphere, BoxPlane, CapsulePlane,
          RevoluteLimit, TranslationalLimit, JointFriction>;

}  // namespace odyn::spatial
