"""A planetary reduction: a sun, a planet on a carrier and a ring gear on coaxial bearings, their
meshes two three-joint couplers. A motor turns the sun at a constant rate omega, a brake holds
the ring, and a load torque T resists the carrier. The carrier then turns at

    omega_c = omega Z_s / (Z_s + Z_r)                     (Willis, with the ring still),

the planet on the carrier at -(Z_s / Z_p) (omega - omega_c), and, the speeds being constant,
the motor needs T Z_s / (Z_s + Z_r) while the brake takes T Z_r / (Z_s + Z_r).

    python examples/python/planetary.py [--teeth SUN PLANET RING] [--load T]
"""

import argparse

import numpy as np

import odyn


def planetary_reduction(teeth=(24, 18, 60), omega=10.0, load=3.0, module=0.002):
    """The set: body names "sun", "ring", "carrier" and "planet"; joints "<body> hinge" and
    "planet pin"; drivers "motor" (the sun) and "brake" (the ring); the meshes "sun mesh" and
    "ring mesh"."""
    z_s, z_p, z_r = teeth
    orbit = module * (z_s + z_p) / 2  # the planet's centre, from the axis
    m = odyn.Model()
    for name, mass, i in (("sun", 0.3, 2e-3), ("ring", 1.0, 0.03), ("carrier", 0.5, 0.01),
                          ("planet", 0.2, 5e-4)):
        m.add_body(name, mass, [i / 2, i / 2, i],
                   position=[0, orbit, 0] if name == "planet" else [0, 0, 0])
        if name != "planet":
            m.add_revolute(f"{name} hinge", "ground", body_b=name)
    m.add_revolute("planet pin", "carrier", on_a={"point": [0, orbit, 0]}, body_b="planet")
    # Seen from the carrier the gears mesh as a fixed train (phi: the planet on the carrier):
    # Z_p phi + Z_s (theta_s - theta_c) = 0 and Z_p phi - Z_r (theta_r - theta_c) = 0.
    m.add_coupler("sun mesh", joint_1="planet pin", scale_1=z_p, joint_2="sun hinge",
                  scale_2=z_s, joint_3="carrier hinge", scale_3=-z_s)
    m.add_coupler("ring mesh", joint_1="planet pin", scale_1=z_p, joint_2="ring hinge",
                  scale_2=-z_r, joint_3="carrier hinge", scale_3=z_r)
    m.add_revolute_driver("motor", odyn.constant_velocity(omega), joint="sun hinge")
    m.add_revolute_driver("brake", odyn.constant_velocity(0.0), joint="ring hinge")
    m.add_point_torque("load", "carrier", [0, 0, -load])
    return m


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--teeth", type=int, nargs=3, default=[24, 18, 60],
                        metavar=("SUN", "PLANET", "RING"))
    parser.add_argument("--load", type=float, default=3.0, help="N m on the carrier")
    args = parser.parse_args()
    z_s, z_p, z_r = args.teeth
    omega = 10.0
    r = odyn.simulate(planetary_reduction(tuple(args.teeth), omega, args.load), t_end=2.0,
                      output_interval=0.01, rtol=1e-10, atol=1e-10)
    carrier = np.diff(r.output("sun mesh", "coordinate_3")) / np.diff(r.t)
    planet = np.diff(r.output("sun mesh", "coordinate_1")) / np.diff(r.t)
    ratio = z_s / (z_s + z_r)
    print(f"carrier speed {carrier.mean():.6f} rad/s (Willis: {omega * ratio:.6f}), planet on "
          f"the carrier {planet.mean():.6f} rad/s ({-z_s / z_p * omega * (1 - ratio):.6f})")
    motor, brake = (r.reaction(name).torque[:, 2] for name in ("motor", "brake"))
    print(f"motor torque {motor.mean():.6f} N m (T Z_s / (Z_s + Z_r): "
          f"{args.load * ratio:.6f}), brake torque {brake.mean():.6f} N m "
          f"(T Z_r / (Z_s + Z_r): {args.load * (1 - ratio):.6f})")


if __name__ == "__main__":
    main()
