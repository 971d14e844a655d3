"""Command line: odyn run SCENE [--analysis KIND] [options], odyn check SCENE, odyn integrators,
odyn elements [TYPE] [--planar] [--module NAME] (also python -m odyn)."""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from typing import Any, List, NoReturn, Optional, Tuple

import numpy as np

from . import _core, _schema, modules
from .kinematics import check
from .model import new_model
from .results import (ADAPTIVE_OPTIONAL, COORDINATES, LINEAR_SOLVERS, Interrupted, Result,
                      chosen_integrator, integrators)
from .linear import LinearModel
from .scene import ANALYSES, TIMED, Scene, load, write_table
from .statics import Modes


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line and exit status 1, like every bad input
        print(f"odyn: {message} (see odyn --help)", file=sys.stderr)
        sys.exit(1)


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="odyn", description="Run odyn scene files (JSON).")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = sub.add_parser("run", help="run a scene's analysis (dynamic unless it names another)")
    run.add_argument("scene", help="scene file (JSON)")
    run.add_argument("--analysis", choices=list(ANALYSES),
                     help="dynamic, kinematic (a fully driven mechanism, with its drivers' "
                     "efforts), quasi_static (equilibria as the drivers move), static (the "
                     "equilibrium), modes (the natural modes about it) or linear (a "
                     "state-space model for the scene's inputs and outputs); default: the "
                     "scene's \"type\", else dynamic")
    run.add_argument("--t-end", type=float, help="end time, s")
    run.add_argument("--h", type=float, dest="step", help="step size, s")
    run.add_argument("--dt-out", type=float, dest="output_interval", help="output interval, s")
    names = list(integrators())
    run.add_argument("--integrator", choices=names, metavar="NAME",
                     help=f"one of {', '.join(names)} (odyn integrators describes them)")
    run.add_argument("--rho-inf", type=float, help="generalized-alpha and hht: rho_inf")
    run.add_argument("--rtol", type=float, help="relative local error tolerance (turns on "
                     "error control for generalized-alpha and hht; --h is then the first step)")
    run.add_argument("--atol", type=float, help="absolute local error tolerance (likewise)")
    run.add_argument("--max-step", type=float, help="largest step with error control, s")
    run.add_argument("--coordinates", choices=COORDINATES,
                     help="absolute, or joint coordinates of a spanning tree (recursive, "
                     "linear in the number of bodies), loops closed by constraints, with any "
                     "model and integrator (default: auto, by the model and the integrator)")
    run.add_argument("--linear-solver", choices=LINEAR_SOLVERS,
                     help="factorization of the linear systems: dense for small models, "
                     "sparse (cholmod, klu) for large ones (default: auto, by size)")
    run.add_argument("--out", help="write the output columns to a .csv or .npz file")
    run.add_argument("--plot", help="draw every output column against t into this image")
    run.add_argument("--figures", nargs="?", const=".", metavar="DIR",
                     help="draw the scene's figures into DIR (default: .)")
    run.add_argument("--gif", help="animate the mechanism into this GIF file (modes: the "
                     "lowest mode)")
    run.add_argument("--quiet", action="store_true", help="no progress bar, no summary")
    check = sub.add_parser("check", help="check a scene file and describe its model")
    check.add_argument("scene")
    sub.add_parser("integrators", help="list the integrators, by name")
    elements = sub.add_parser("elements", help="list the element types, or one type's parameters")
    elements.add_argument("type", nargs="?", help="an element type: its parameters")
    elements.add_argument("--planar", action="store_true", help="the planar catalogue")
    elements.add_argument("--module", metavar="NAME",
                          help="the types a module of one's own compiles (odyn.modules)")
    return p


class _Progress:
    """A progress bar on stderr, shown only on a terminal and once a run has lasted 1 s. The
    time left is extrapolated from the stepping so far, not from the setup (assembly and the
    integrator's analysis), which comes before the first call."""

    def __init__(self, t_end: float, enabled: bool) -> None:
        self.t_end, self.enabled, self.start, self.shown = t_end, enabled, time.monotonic(), False
        self.stepping_from: Optional[Tuple[float, float]] = None  # (wall time, fraction)

    def __call__(self, t: float) -> None:
        now = time.monotonic()
        fraction = min(1.0, t / self.t_end) if self.t_end > 0 else 1.0
        if self.stepping_from is None:
            self.stepping_from = (now, fraction)
        elapsed = now - self.start
        if not self.enabled or elapsed < 1.0:
            return
        bar = "#" * int(30 * fraction)
        wall0, fraction0 = self.stepping_from
        left = (f"left ~{(now - wall0) * (1.0 - fraction) / (fraction - fraction0):.1f} s"
                if fraction > fraction0 else "left: estimating")
        sys.stderr.write(f"\r[{bar:<30}] {100 * fraction:5.1f}%  t = {t:.4g} s  "
                         f"elapsed {elapsed:.1f} s (setup {wall0 - self.start:.1f} s), {left} ")
        sys.stderr.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()


def describe_integrator(settings: dict) -> str:
    """"generalized-alpha (rho_inf 0.9), h = 0.0001 s" or, with error control, "... rtol ..."."""
    name = chosen_integrator(settings)
    step = settings.get("step", 1e-4)
    text = name + (f" (rho_inf {settings.get('rho_inf', 0.9):g})"
                   if name in ADAPTIVE_OPTIONAL else "")
    adaptive = settings.get("adaptive")
    if adaptive is None:  # as simulate(): tolerances turn on error control
        adaptive = name not in ADAPTIVE_OPTIONAL or "rtol" in settings or "atol" in settings
    if adaptive:
        text += (f", error control rtol {settings.get('rtol', 1e-6):g}, atol "
                 f"{settings.get('atol', 1e-6):g}")
        if name != "auto":
            text += f", first step {step:g} s"
        if settings.get("max_step"):
            text += f", max step {settings['max_step']:g} s"
        return text
    return text + f", h = {step:g} s"


def summary_lines(scene: Scene, result: Result, settings: dict, wall: float) -> List[str]:
    s = result.summary or {}
    lines = [f"{describe_integrator(settings)}, t_end = {settings['t_end']:g} s: "
             f"{len(result)} outputs" + ("  [INTERRUPTED]" if result.interrupted else "")]
    m = scene.model
    lines.append(f"  {m.space} model: {m.num_velocities} coordinates, {m.num_equations} "
                 "constraint equations")
    if s and s.get("integrator_choice"):
        lines.append(f"  {s['integrator_choice']}")
    if s and s.get("coordinates_choice"):
        lines.append(f"  {s['coordinates_choice']}")
    if s:
        steps = s["steps"]
        lines.append(f"  steps {steps} (law switches {s['events']}, rejected "
                     f"{s['rejected_steps']}), "
                     f"Newton iterations {s['newton_iterations']} "
                     f"({s['newton_iterations'] / max(steps, 1):.2f} per step), "
                     f"Jacobians {s['jacobian_evaluations']}, "
                     f"factorizations {s['factorizations']}")
        lines.append(f"  largest local error estimate {s['max_error_estimate']:.3g} "
                     "(in units of rtol, atol)")
        if s.get("singular_steps"):
            lines.append(f"  {s['singular_steps']} steps ended near a singular configuration "
                         "(constraint Jacobian nearly rank-deficient; see docs/hard-cases.md)")
        stepping = s["wall_seconds"] - s["setup_seconds"]
        lines.append(f"  wall time {s['wall_seconds']:.3f} s: setup {s['setup_seconds']:.3f} s, "
                     f"steps {stepping:.3f} s ({1e6 * stepping / max(steps, 1):.2f} us per step)")
    else:
        lines.append(f"  stopped at t = {result.t[-1] if len(result) else 0.0:g} s "
                     f"after {wall:.3f} s")
    if result.events:
        lines.append(f"  events ({len(result.events)}): " + ", ".join(
            f"{e.name} {e.direction} at {e.time:.9g} s" for e in result.events[:8])
            + (", ..." if len(result.events) > 8 else ""))
    if result.ended_by:
        lines.append(f"  ended by the terminal event '{result.ended_by}' at t = "
                     f"{result.events[-1].time:.9g} s")
    if result.redundant_equations:
        lines.append("  redundant constraint equations (minimum-norm reactions): " + ", ".join(
            f"{e['joint']} (equation {e['equation']})" for e in result.redundant_equations))
    if len(result):
        lines.append(f"  largest residuals: |Phi| {np.max(result.phi_norm):.2e}, "
                     f"|Phi_q v + Phi_t| {np.max(result.phid_norm):.2e}")
        e = result.total_energy
        working = working_elements(scene.model)
        energy = (f"  energy (kinetic + potential): {e[0]:.6g} J at t = 0, {e[-1]:.6g} J "
                  "at the end; ")
        if working:
            named = ", ".join(working[:4]) + (f" and {len(working) - 4} more"
                                               if len(working) > 4 else "")
            lines.append(energy + f"it changes by up to {result.energy_drift():.3g} J "
                         f"through the work of {named} (not an error)")
        else:
            lines.append(energy + f"largest drift {result.energy_drift():.3g} J (every force "
                         "has a potential here, so this is the integration's error)")
        final = scene.columns(result)
        shown = [f"{k} {v[-1]:.6g}" for k, v in final.items() if k != "t"][:6]
        if shown:
            lines.append("  final: " + ", ".join(shown))
    return lines


#: The options of `odyn run` that set an analysis's settings, by setting.
_SETTING_OPTIONS = {"t_end": "--t-end", "step": "--h", "output_interval": "--dt-out",
                    "integrator": "--integrator", "rho_inf": "--rho-inf", "rtol": "--rtol",
                    "atol": "--atol", "max_step": "--max-step", "coordinates": "--coordinates",
                    "linear_solver": "--linear-solver"}


def _settings(args: argparse.Namespace, scene: Scene, kind: str) -> dict:
    """The scene's settings for the analysis `kind`, with the command line's options."""
    takes = set(ANALYSES[kind]) | ({"t_end", "output_interval"} if kind in TIMED else set())
    wrong = [option for key, option in _SETTING_OPTIONS.items()
             if getattr(args, key) is not None and key not in takes]
    if wrong:
        raise ValueError(f"{', '.join(wrong)}: not a setting of a {kind} analysis")
    settings = {k: v for k, v in scene.analysis.items() if k in takes}
    for key in _SETTING_OPTIONS:
        value = getattr(args, key)
        if value is not None:
            settings[key] = value
    if kind != "dynamic":
        return settings
    if chosen_integrator(settings) not in ADAPTIVE_OPTIONAL:
        settings.pop("adaptive", None)  # the scene's choice for another integrator
    elif args.rtol is not None or args.atol is not None:
        settings["adaptive"] = True  # as the C++ examples: tolerances turn on error control
    return settings


# Force types whose forces all have a potential in the model's energy, unless one of the
# parameters named gives them a damper, an actuator, a law of one's own or friction.
_CONSERVATIVE_UNLESS = {
    "gravity": (), "tsda": ("damping", "actuator"), "rsda": ("damping", "actuator"),
    "bushing": ("damping", "law"), "revolute_limit": ("dissipation",),
    "translational_limit": ("dissipation",),
    **{contact: ("dissipation", "friction") for contact in (
        "sphere_plane", "sphere_sphere", "box_plane", "capsule_plane", "circle_line",
        "circle_circle", "rectangle_line", "capsule_line")},
}


def _nonzero(value: Any) -> bool:
    if value is None:
        return False
    if isinstance(value, (int, float)):
        return value != 0
    if isinstance(value, (list, tuple)):
        return any(_nonzero(v) for v in value)
    return True  # a function, or a motion


def working_elements(model: Any) -> List[str]:
    """The elements whose work the kinetic + potential energy leaves out: drivers, Python
    constraints (which may move with time), dampers, actuators, friction, and loads without a
    potential (point loads, Python forces, a module's forces)."""
    out = []
    for name in model.element_names:
        kind = model.element_type(name)
        category = _schema.KNOWN[model.space].get(kind, {}).get("category")
        if category == "driver" or kind == "user_constraint":
            out.append(name)
        elif category != "joint" and (kind not in _CONSERVATIVE_UNLESS or any(
                _nonzero(model.element(name).get(key)) for key in _CONSERVATIVE_UNLESS[kind])):
            out.append(name)
    return out


def _probe_writable(option: str, given: str, path: str) -> None:
    """Creates and removes `path`, so that a file the run would write at its end (for the
    option's value `given`) is known to be writable before the run starts (permissions,
    read-only or special file systems)."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise ValueError(f"{option} {given}: the folder {folder} does not exist; create it "
                         "first")
    try:
        with open(path, "xb"):
            pass
        os.remove(path)
    except FileExistsError:
        if not os.access(path, os.W_OK):
            raise ValueError(f"{option} {given}: not writable here (permission denied); choose "
                             "another place") from None
    except OSError as e:
        raise ValueError(f"{option} {given}: cannot be written here ({e.strerror}); choose "
                         "another place") from None


def _check_output_path(path: str) -> None:
    """Refuses, before any work, an --out that could not be written at the end (it is written
    beside its place, then renamed: see write_table)."""
    if not path.endswith((".csv", ".npz")):
        raise ValueError(f"--out {path}: expected a .csv or .npz file name")
    if os.path.isdir(path):
        raise ValueError(f"--out {path}: is a directory; give a file name")
    _probe_writable("--out", path, path + ".part")


def _check_drawings(args: argparse.Namespace) -> None:
    """Refuses, before any work, a --plot, --gif or --figures that could not be drawn."""
    if args.gif:
        if not args.gif.lower().endswith(".gif"):
            raise ValueError(f"--gif {args.gif}: expected a .gif file name")
        _probe_writable("--gif", args.gif, args.gif)
    if args.plot:
        from matplotlib.figure import Figure
        formats = Figure().canvas.get_supported_filetypes()
        extension = os.path.splitext(args.plot)[1].lstrip(".").lower()
        if extension not in formats:
            raise ValueError(f"--plot {args.plot}: expected a file name ending in one of "
                             f"{', '.join('.' + f for f in sorted(formats))}")
        _probe_writable("--plot", args.plot, args.plot)
    if args.figures is not None:
        try:
            os.makedirs(args.figures, exist_ok=True)
        except OSError as e:
            raise ValueError(f"--figures {args.figures}: cannot create the folder ({e.strerror}); "
                             "choose another place") from None
        _probe_writable("--figures", args.figures, os.path.join(args.figures, ".odyn-write-test"))


def _run(args: argparse.Namespace) -> int:
    scene = load(args.scene)
    kind = args.analysis or scene.analysis_type
    settings = _settings(args, scene, kind)
    if args.out:
        _check_output_path(args.out)
    if kind not in TIMED:
        drawn = [o for o, v in (("--plot", args.plot), ("--figures", args.figures),
                                ("--gif", None if kind == "modes" else args.gif))
                 if v is not None]
        if drawn:
            raise ValueError(f"{', '.join(drawn)}: draws a run against time; a {kind} analysis "
                             "gives one configuration")
        _check_drawings(args)  # a mode's --gif
        if kind == "linear":
            return _run_linear(args, scene, settings)
        return _run_at_rest(args, scene, kind, settings)
    _check_drawings(args)
    progress = _Progress(settings["t_end"], not args.quiet and sys.stderr.isatty())
    start = time.monotonic()
    interrupted = False
    try:
        result = scene.run(kind, progress=progress, **settings)
    except Interrupted as stop:
        result, interrupted = stop.result, True
    except _core.Error as e:
        progress.close()
        partial = getattr(e, "result", None)
        if partial is not None and args.out and len(partial):
            write_table(scene.columns(partial), args.out)
            print(f"odyn: the {len(partial)} rows before the error, to t = {partial.t[-1]:g} s, "
                  f"were written to {args.out}", file=sys.stderr)
        raise
    finally:
        progress.close()
    wall = time.monotonic() - start
    table = scene.columns(result)
    if args.out:
        write_table(table, args.out)
    if args.plot:
        from .plot import all_columns
        all_columns(table, args.plot, title=os.path.basename(args.scene))
    if args.figures is not None:
        from .plot import scene_figures
        os.makedirs(args.figures, exist_ok=True)
        scene_figures(scene.figures, table, args.figures)
    if args.gif:
        from .plot import animate
        animate(result, scene.model, args.gif, title=os.path.basename(args.scene))
    if not args.quiet:
        target = f" -> {args.out}" if args.out else ""
        print(f"odyn: {args.scene}{target}")
        lines = (summary_lines(scene, result, settings, wall) if kind == "dynamic"
                 else kinematic_lines(scene, result, settings, wall, kind))
        print("\n".join(lines))
    if interrupted:
        print(f"odyn: interrupted; kept {len(result)} outputs up to t = "
              f"{result.t[-1] if len(result) else 0.0:g} s", file=sys.stderr)
        return 130
    return 0


def _final_columns(scene: Scene, result: Result) -> List[str]:
    final = scene.columns(result)
    shown = [f"{k} {v[-1]:.6g}" for k, v in final.items() if k != "t"][:6]
    return ["  final: " + ", ".join(shown)] if shown else []


def kinematic_lines(scene: Scene, result: Result, settings: dict, wall: float,
                    kind: str = "kinematic") -> List[str]:
    """The summary of a kinematic or quasi-static analysis: its residuals and its drivers'
    largest efforts."""
    m = scene.model
    lines = [f"{kind.replace('_', '-')} analysis, t_end = {settings['t_end']:g} s: "
             f"{len(result)} outputs" + ("  [INTERRUPTED]" if result.interrupted else ""),
             f"  {m.space} model: {m.num_velocities} coordinates, {m.num_equations} constraint "
             f"equations, wall time {wall:.3f} s"]
    if len(result):
        residual = f"  largest residual: |Phi| {np.max(result.phi_norm):.2e}"
        if result.statics:
            residual += (", force imbalance "
                         f"{max(row['force_residual'] for row in result.statics):.2e}")
        lines.append(residual)
        for name in result.joint_names:
            if m.element_type(name) in _schema.DRIVERS:
                r = result.reaction(name)
                effort = r.force if m.element_type(name) == "translational_driver" else r.torque
                size = np.abs(effort) if effort.ndim == 1 else np.linalg.norm(effort, axis=1)
                unit = "N" if m.element_type(name) == "translational_driver" else "N m"
                lines.append(f"  driver {name}: largest effort {np.max(size):.6g} {unit}")
        lines += _final_columns(scene, result)
    return lines


def static_lines(scene: Scene, result: Result) -> List[str]:
    s = result.statics or {}
    lines = [f"static equilibrium by {s['method']}: {s['iterations']} iterations"
             + (f", {s['load_steps']} load steps" if s["load_steps"] else ""),
             f"  residuals: |Phi| {s['constraint_residual']:.2e}, force imbalance "
             f"{s['force_residual']:.2e} (of loads {s['force_scale']:.3g})"]
    squared = np.asarray(s["squared_frequencies"])
    state = "stable" if s["stable"] else "neutral" if s["neutral"] else "UNSTABLE"
    lowest = f", lowest omega^2 {squared[0]:.6g} 1/s^2" if len(squared) else ""
    lines.append(f"  {state}{lowest}; least stiff: {', '.join(s['least_stiff']) or '-'}")
    return lines + _final_columns(scene, result)


def mode_table(found: Modes) -> dict:
    """The modes as columns: mode, frequency (Hz, undamped), and the damped eigenvalues'
    natural_frequency (Hz), damped_frequency (Hz) and damping_ratio, each list padded with NaN
    to the longer one (an overdamped mode has two real eigenvalues)."""
    columns = {"frequency": found.frequencies, "natural_frequency": found.natural_frequencies,
               "damped_frequency": found.damped_frequencies,
               "damping_ratio": found.damping_ratios}
    n = max(len(v) for v in columns.values())
    out = {"mode": np.arange(1, n + 1, dtype=float)}
    for name, values in columns.items():
        out[name] = np.concatenate([np.asarray(values, dtype=float),
                                    np.full(n - len(values), np.nan)])
    return out


def _run_at_rest(args: argparse.Namespace, scene: Scene, kind: str, settings: dict) -> int:
    """A static or modal analysis: one configuration, no time."""
    start = time.monotonic()
    outcome = scene.run(kind, **settings)
    wall = time.monotonic() - start
    found = outcome if isinstance(outcome, Modes) else None
    result = found.equilibrium if found is not None else outcome
    if args.out:
        write_table(mode_table(found) if found is not None else scene.columns(result), args.out)
    if found is not None and args.gif and len(found):
        found.animate(0, args.gif)
    if args.quiet:
        return 0
    target = f" -> {args.out}" if args.out else ""
    print(f"odyn: {args.scene}{target}")
    m = scene.model
    print(f"{kind} analysis: {m.space} model, {m.num_velocities} coordinates, "
          f"{m.num_equations} constraint equations, wall time {wall:.3f} s")
    if found is None:
        print("\n".join(static_lines(scene, result)))
    else:
        print("\n".join([f"  about the equilibrium, |Phi| {result.phi_norm[0]:.2e}"]
                        + _final_columns(scene, result)))
        shown = 12
        table = mode_table(found)
        count = len(found.frequencies)
        print(f"  {count} mode{'' if count == 1 else 's'}; the lowest (undamped frequency, Hz; "
              "the damped eigenvalues' natural frequency, Hz, and damping ratio):")
        for i in range(min(len(table["mode"]), shown)):
            print(f"  {i + 1:4d}  {table['frequency'][i]:12.6g}  "
                  f"{table['natural_frequency'][i]:12.6g}  {table['damping_ratio'][i]:9.4g}")
    return 0


def eigenvalue_table(found: LinearModel) -> dict:
    """A state-space model's eigenvalues as columns: real and imag (1/s), natural_frequency
    (|s| / 2 pi, Hz) and damping_ratio (-Re s / |s|; NaN at s = 0)."""
    s = found.eigenvalues
    size = np.abs(s)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(size > 0, -s.real / size, np.nan)
    return {"eigenvalue": np.arange(1, len(s) + 1, dtype=float), "real": s.real, "imag": s.imag,
            "natural_frequency": size / (2 * np.pi), "damping_ratio": ratio}


def _run_linear(args: argparse.Namespace, scene: Scene, settings: dict) -> int:
    """A linear analysis: the state-space model to an .npz file (its matrices and names), or
    its eigenvalues to a .csv file, and a summary."""
    start = time.monotonic()
    found = scene.run("linear", **settings)
    assert isinstance(found, LinearModel)
    wall = time.monotonic() - start
    table = eigenvalue_table(found)
    if args.out and args.out.endswith(".npz"):
        np.savez(args.out, a=found.a, b=found.b, c=found.c, d=found.d, drift=found.drift,
                 outputs_at_state=found.outputs_at_state, basis=found.basis,
                 coordinates=np.array(found.coordinates, dtype=str),
                 inputs=np.array(found.inputs, dtype=str),
                 outputs=np.array(found.outputs, dtype=str),
                 states=np.array(found.states, dtype=str), eigenvalues=found.eigenvalues)
    elif args.out:
        write_table(table, args.out)
    if args.quiet:
        return 0
    target = f" -> {args.out}" if args.out else ""
    print(f"odyn: {args.scene}{target}")
    m = scene.model
    about = "the equilibrium" if settings.get("find_equilibrium") else "the initial state"
    print(f"linear analysis about {about}: {m.space} model, {m.num_velocities} coordinates, "
          f"wall time {wall:.3f} s")
    k = found.degrees_of_freedom
    print(f"  {2 * k} states ({k} degree{'' if k == 1 else 's'} of freedom), "
          f"{len(found.inputs)} inputs ({', '.join(found.inputs) or '-'}), "
          f"{len(found.outputs)} outputs ({', '.join(found.outputs) or '-'})")
    print(f"  |drift| {np.linalg.norm(found.drift):.2e} (zero at an equilibrium)")
    shown = min(len(table["real"]), 12)
    if shown:
        print("  eigenvalues, smallest first (real, imaginary, 1/s; natural frequency, Hz; "
              "damping ratio):")
    for i in range(shown):
        print(f"  {i + 1:4d}  {table['real'][i]:12.6g}  {table['imag'][i]:12.6g}  "
              f"{table['natural_frequency'][i]:12.6g}  {table['damping_ratio'][i]:9.4g}")
    return 0


def _check(args: argparse.Namespace) -> int:
    """The scene's validity, its model and analysis, and the model report (odyn.check): the
    degrees of freedom, the redundant equations and what the assembly did."""
    scene = load(args.scene)
    m = scene.model
    print(f"odyn: {args.scene}: valid scene")
    print(f"  {m.space} model: {m.num_bodies} moving bodies ({', '.join(m.body_names[1:])}), "
          f"{len(m.element_names)} elements")
    a = scene.analysis
    kind = scene.analysis_type
    if kind == "dynamic":
        print(f"  analysis: {describe_integrator(a)}, t_end {a['t_end']:g} s, output every "
              f"{a['output_interval']:g} s")
    elif kind in TIMED:
        coordinates = f", in {a.get('coordinates', 'absolute')} coordinates" * (
            kind == "quasi_static")
        print(f"  analysis: {kind.replace('_', '-')}, t_end {a['t_end']:g} s, output every "
              f"{a['output_interval']:g} s{coordinates}")
    elif kind == "linear":
        about = "the equilibrium" if a.get("find_equilibrium") else "the initial state"
        print(f"  analysis: linear about {about}, in {a.get('coordinates', 'absolute')} "
              f"coordinates; inputs: {', '.join(a.get('inputs', {})) or '-'}; outputs: "
              + (", ".join(o if isinstance(o, str) else ".".join(o)
                           for o in a.get("outputs", [])) or "-"))
    else:
        print(f"  analysis: {kind}, in {a.get('coordinates', 'absolute')} coordinates")
    print(f"  outputs: t, {', '.join(o['name'] for o in scene.outputs)}")
    if m.event_names:
        print(f"  events: {', '.join(m.event_names)}")
    try:
        report = check(m)
    except _core.AssemblyError as e:
        print(f"  the model does not assemble: {e}")
        return 1
    print("\n".join("  " + line for line in report.lines()))
    return 0


def _integrators() -> int:
    for name, what in integrators().items():
        print(f"{name:20} {what}")
    return 0


def _elements(element_type: Optional[str], planar: bool, module: Optional[str] = None) -> int:
    """The catalogue of a space as its elements describe themselves (docs/elements.md has it
    all), or the types a module of one's own compiles."""
    space = "planar" if planar else "spatial"
    catalogue = _schema.DESCRIPTIONS[space]
    if module is not None:
        compiled = new_model(space, modules.load(module, "--module")).element_types
        catalogue = {t: _schema.KNOWN[space][t] for t in compiled}
    if element_type is None:
        for name, d in catalogue.items():
            print(f"{name:22} {d['category']:7} {d['summary']}")
        return 0
    if element_type not in catalogue:
        raise ValueError(f"no {space} element type '{element_type}'; the {space} types are: "
                         + ", ".join(catalogue))
    d = catalogue[element_type]
    print(f"{element_type} ({space} {d['category']}): {d['summary']}")
    for p in d["parameters"]:
        default = "required" if p["default"] is None else f"default {p['default']}"
        unit = f", {p['unit']}" if p["unit"] else ""
        print(f"  {p['name']:22} {p['kind']}{unit}; {default}. {p['doc']}")
    if d["outputs"]:
        print("outputs (scene column {\"element\": NAME, \"output\": ...}):")
        for o in d["outputs"]:
            unit = f" ({o['unit']})" if o["unit"] else ""
            print(f"  {o['name']:22} {o['doc'] or '-'}{unit}")
    if d["state_fields"]:
        print("state (scene column {\"state\": NAME, \"field\": ...}):")
        for o in d["state_fields"]:
            unit = f" ({o['unit']})" if o["unit"] else ""
            print(f"  {o['name']:22} {o['doc']}{unit}")
    return 0


def _format_warning(message, category, filename, lineno, line=None) -> str:
    """A warning as one line, "odyn: warning: ...": the source line of the library that issued
    it means nothing to the user of a scene."""
    return f"odyn: warning: {message}\n"


def main(argv: Optional[List[str]] = None) -> int:
    args = _parser().parse_args(argv)
    formatter, warnings.formatwarning = warnings.formatwarning, _format_warning
    try:
        if args.command == "integrators":
            return _integrators()
        if args.command == "elements":
            return _elements(args.type, args.planar, args.module)
        return _run(args) if args.command == "run" else _check(args)
    except (_core.Error, ValueError, OSError) as e:
        print(f"odyn: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # outside a run (which keeps its outputs): nothing to keep
        print("odyn: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.formatwarning = formatter


if __name__ == "__main__":
    sys.exit(main())
