"""What a force written in Python costs per call, on the engine model (examples/engine.json).

Each variant adds one Python force element to the engine and runs the standard 1 s analysis
(h = 1e-4). The variants that add a zero force leave the dynamics, and so the number of calls,
unchanged: (run time - run time of the plain engine) / calls is the cost of one call, bridge and
function body together. The last variant replaces the C++ viscous load (an Rsda) by the same
torque written in Python.

    .venv/bin/python bench/python_user_force.py [--repeat 5]
"""

import argparse
import pathlib
import time

import odyn

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "engine.json"


def engine(extra=None, python_load=False):
    scene = odyn.load(SCENE)
    d = scene.to_dict()
    if python_load:
        d["forces"] = [f for f in d["forces"] if f["name"] != "load"]
    scene = odyn.scene.from_dict(d)
    if python_load:
        scene.model.add_point_torque(name="load", body="crank",
                                     torque=lambda t, b: (-0.1 * b.angular_velocity[0], 0.0, 0.0))
    if extra:
        extra(scene.model)
    return scene


def best_time(scene, repeat):
    best, result = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        result = scene.simulate()
        best = min(best, time.perf_counter() - start)
    return best, result


def count_calls(make_extra):
    calls = [0]

    def counting(function):
        def counted(*args):
            calls[0] += 1
            return function(*args)
        return counted
    odyn_scene = engine(lambda m: make_extra(m, counting))
    odyn_scene.simulate()
    return calls[0]


VARIANTS = {
    "point_torque, returns a tuple of zeros":
        lambda m, wrap=lambda f: f: m.add_point_torque(
            name="extra", body="crank", torque=wrap(lambda t, b: (0.0, 0.0, 0.0))),
    "point_force reading the body's state (numpy scalars)":
        lambda m, wrap=lambda f: f: m.add_point_force(
            name="extra", body="piston",
            force=wrap(lambda t, b: (0.0 * b.position[2], 0.0, 0.0 * b.linear_velocity[2]))),
    "user_force on two bodies, returns 2 x 6 zeros":
        lambda m, wrap=lambda f: f: m.add_user_force(
            name="extra", bodies=["crank", "piston"],
            function=wrap(lambda t, a, b: ((0.0,) * 6, (0.0,) * 6))),
    "tsda actuator(t, length, rate) -> 0.0":
        lambda m, wrap=lambda f: f: m.add_tsda(
            name="extra", body_a="ground", point_a=[0, 0, 0.5], body_b="piston",
            point_b=[0, 0, 0], actuator=wrap(lambda t, length, rate: 0.0)),
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    base, base_result = best_time(engine(), args.repeat)
    steps = base_result.summary["steps"]
    print(f"engine, 1 s at h = 1e-4 ({steps} steps), C++ elements only: {base * 1e3:.1f} ms")
    print(f"{'variant':56s} {'calls':>7s} {'run ms':>7s} {'us/call':>8s}")
    for name, make in VARIANTS.items():
        calls = count_calls(make)
        elapsed, result = best_time(engine(make), args.repeat)
        assert result.summary["steps"] == steps  # a zero force changes nothing
        print(f"{name:56s} {calls:7d} {elapsed * 1e3:7.1f} "
              f"{(elapsed - base) / calls * 1e6:8.2f}")
    elapsed, result = best_time(engine(python_load=True), args.repeat)
    print(f"load torque -0.1 omega_x in Python instead of the C++ Rsda: {elapsed * 1e3:.1f} ms "
          f"({result.summary['steps']} steps, {result.summary['newton_iterations']} Newton "
          f"iterations; theta(1) {result.state('gas force')['theta'][-1]:.6f} rad vs "
          f"{base_result.state('gas force')['theta'][-1]:.6f} with the Rsda)")


if __name__ == "__main__":
    main()
