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
