#pragma once
// The planar element catalogue and the model types built from it. A planar model instantiates
// only planar code: 3 coordinates per body and 2-equation pins.

#include "odyn/core/coupler.hpp"
#include "odyn/core/gear_pairs.hpp"
#include "odyn/core/model.hpp"
#include "odyn/forces/contact.hpp"
#include "odyn/forces/gravity.hpp"
#include "odyn/forces/joint_friction.hpp"
#include "odyn/forces/point_load.hpp"
#include "odyn/forces/tsda.hpp"
#include "odyn/planar/body.hpp"
#include "odyn/planar/bushing.hpp"
#include "odyn/planar/composite.hpp"
#include "odyn/planar/distance.hpp"
#include "odyn/planar/drivers.hpp"
#include "odyn/planar/fixed.hpp"
#include "odyn/planar/joint_primitives.hpp"
#include "odyn/planar/limits.hpp"
#include "odyn/planar/revolute.hpp"
#include "odyn/planar/rsda.hpp"
#include "odyn/planar/translational.hpp"

namespace odyn::planar {

using Gravity = GravityField<Planar>;
using PointForce = PointForceT<Planar>;
using PointTorque = PointTorqueT<Planar>;
using Tsda = TsdaT<Planar>;
using CircleLine = SpherePlaneT<Planar>;
using CircleCircle = SphereSphereT<Planar>;
using RectangleLine = BoxPlaneT<Planar>;
using CapsuleLine = CapsulePlaneT<Planar>;
using Gear = GearT<PairJoint, JointFrame>;
using RackPinion = RackPinionT<PairJoint, JointFrame>;
using Coupler = CouplerT<PairJoint, JointFrame>;
using JointFriction = JointFrictionT<PairJoint>;

/// The joint types a turning_joint (its angle), a sliding_joint (its slide) or a coupled_joint
/// (either) parameter names.
inline constexpr auto turning_joint_types = parameters::revolute_joints;
inline constexpr auto sliding_joint_types = parameters::translational_joints;
inline constexpr auto coupled_joint_types = parameters::planar_coupled_joints;

/// A planar model holding just the element types a scene lists.
template <class... Elements>
using Model = odyn::Model<Body, Elements...>;

/// Every planar element type of the library (what scripting uses).
using DefaultModel =
    Model<Revolute, Translational, Fixed, Distance, InLine, Gear, RackPinion, Coupler,
          RevoluteDriver, TranslationalDriver, Gravity, PointForce, PointTorque, Tsda, Rsda,
          Bushing, CircleLine, CircleCircle, RectangleLine, CapsuleLine, RevoluteLimit,
          TranslationalLimit, JointFriction>;

}  // namespace odyn::planar
