"""Time histories with matplotlib (imported only when a figure is drawn; Agg backend if no
display is set up)."""

from __future__ import annotations

import os
from typing import Any, Dict, Mapping, Optional, Sequence, Union

import numpy as np

Table = Mapping[str, np.ndarray]


def _pyplot():
    import matplotlib
    if not os.environ.get("DISPLAY") and not os.environ.get("MPLBACKEND"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def time_history(table: Table, y: Union[str, Sequence[str]], path: Optional[str] = None, *,
                 title: str = "", ylabel: str = "", offset: float = 0.0, scale: float = 1.0,
                 ax: Any = None) -> Any:
    """Plots columns of a table (a dict of arrays with "t", e.g. Scene.columns(result)) against
    t: (value + offset) * scale. Saves to `path` if given; returns the matplotlib Axes."""
    plt = _pyplot()
    names = [y] if isinstance(y, str) else list(y)
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(8, 4.5), layout="constrained")
    t = np.asarray(table["t"])
    for name in names:
        ax.plot(t, (np.asarray(table[name]) + offset) * scale, label=name, linewidth=1.0)
    ax.set_xlabel("t  [s]")
    ax.set_ylabel(ylabel or ", ".join(names))
    if title:
        ax.set_title(title)
    if len(names) > 1:
        ax.legend()
    ax.grid(True, alpha=0.3)
    if own and path:
        ax.figure.savefig(path, dpi=120)
        plt.close(ax.figure)
    return ax


def all_columns(table: Table, path: str, title: str = "") -> None:
    """One stacked panel per column of the table (t is the common abscissa)."""
    plt = _pyplot()
    names = [n for n in table if n != "t"]
    fig, axes = plt.subplots(max(1, len(names)), 1, sharex=True, layout="constrained",
                             figsize=(8, 1.8 + 1.6 * len(names)), squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        time_history(table, name, ax=ax)
        ax.set_xlabel("")
    axes[-1, 0].set_xlabel("t  [s]")
    if title:
        fig.suptitle(title)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def scene_figures(figures: Sequence[Mapping[str, Any]], table: Table,
                  directory: str = ".") -> Dict[str, str]:
    """Draws a scene's figures ({"file", "y", "title", "ylabel", "offset", "scale"}) into
    `directory`; returns file paths by figure file name."""
    written = {}
    for spec in figures:
        path = os.path.join(directory, spec["file"])
        time_history(table, spec["y"], path, title=spec.get("title", ""),
                     ylabel=spec.get("ylabel", ""), offset=spec.get("offset", 0.0),
                     scale=spec.get("scale", 1.0))
        written[spec["file"]] = path
    return written


def _rotations(quaternions: np.ndarray) -> np.ndarray:
    """(n, 3, 3) body-to-global rotations from (n, 4) unit quaternions w, x, y, z."""
    w, x, y, z = (quaternions[:, i] for i in range(4))
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def _attachments(model: Any) -> list:
    """(body, local point) pairs, one pair per joint or two-point force: what links bodies."""
    links = []
    for name in model.element_names:
        p = model.element(name)
        if "on_a" in p:
            links.append(((p["body_a"], p["on_a"]["point"]), (p["body_b"], p["on_b"]["point"])))
        elif "point_a" in p:
            links.append(((p["body_a"], p["point_a"]), (p["body_b"], p["point_b"])))
    return links


def _planar_rotations(angles: np.ndarray) -> np.ndarray:
    """(n, 2, 2) body-to-global rotations from (n,) angles."""
    c, s = np.cos(angles), np.sin(angles)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def animate(result: Any, model: Any, path: str, *, frames: int = 60, fps: int = 15,
            title: str = "") -> None:
    """A GIF of any mechanism (spatial in 3D, planar in the plane): each body a dot at its
    centre of mass with sticks to the points where joints and springs attach it; each link
    drawn between its two points."""
    plt = _pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter

    planar = getattr(result, "space", "spatial") == "planar"
    names = result.body_names
    rotations = {b: _planar_rotations(result.body(b).angle) if planar
                 else _rotations(result.body(b).orientation) for b in names}
    centres = {b: result.body(b).position for b in names}

    def point(body: str, local: Sequence[float], k: int) -> np.ndarray:
        if body == "ground":
            return np.asarray(local, dtype=float)
        return centres[body][k] + rotations[body][k] @ np.asarray(local, dtype=float)

    links = _attachments(model)
    picks = np.unique(np.linspace(0, len(result.t) - 1, min(frames, len(result.t))).astype(int))
    everything = np.concatenate([centres[b] for b in names] + [
        np.array([point(b, local, k) for k in picks]) for link in links for b, local in link])
    low, high = everything.min(axis=0), everything.max(axis=0)
    middle, half = (low + high) / 2, max(1e-3, float(np.max(high - low)) / 2 * 1.1)

    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot() if planar else fig.add_subplot(projection="3d")

    def draw(i: int) -> None:
        k = picks[i]
        ax.cla()
        for (ba, pa), (bb, pb) in links:
            a, b = point(ba, pa, k), point(bb, pb, k)
            for body, attach in ((ba, a), (bb, b)):
                if body != "ground":
                    c = centres[body][k]
                    ax.plot(*zip(c, attach), color="tab:blue", linewidth=2)
            ax.plot(*zip(a, b), color="tab:red", linewidth=1)
        for body in names:
            ax.scatter(*centres[body][k], color="tab:blue", s=20)
        ax.set_xlim(middle[0] - half, middle[0] + half)
        ax.set_ylim(middle[1] - half, middle[1] + half)
        if planar:
            ax.set_aspect("equal")
            ax.set_xlabel("x  [m]")
            ax.set_ylabel("y  [m]")
        else:
            ax.set_zlim(middle[2] - half, middle[2] + half)
            ax.set_xlabel("X")
            ax.set_ylabel("Y")
            ax.set_zlabel("Z")
        ax.set_title(f"{title}  t = {result.t[k]:.3f} s".strip())

    animation = FuncAnimation(fig, draw, frames=len(picks))
    animation.save(path, writer=PillowWriter(fps=fps))
    plt.close(fig)
