"""Pictures of the abstract map with matplotlib (imported only when drawing).

Masses are dots with their names, springs are lines coloured by kind, fixed
points (observed tags and the start) are squares, the goal estimate a star.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .clauses import START_ANCHOR, is_anchor
from .files import atomic_path

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from .model import AbstractMap

SPRING_STYLE: dict[str, dict[str, Any]] = {
    "distance": {"color": "tab:blue", "lw": 0.6, "alpha": 0.35},
    "global_angle": {"color": "tab:orange", "lw": 1.0, "alpha": 0.7, "ls": "--"},
    "relative_angle": {"color": "tab:green", "lw": 1.0, "alpha": 0.7, "ls": ":"},
}
FIXED_STYLE: dict[str, dict[str, Any]] = {
    "label": {"marker": "s", "color": "black", "ms": 5},
    "sign": {"marker": "s", "color": "tab:red", "ms": 6},
    "start": {"marker": "o", "color": "tab:purple", "ms": 8},
}


def draw_abstract_map(model: AbstractMap, ax: Axes | None = None, *, labels: bool = True,
                      springs: bool = True) -> Axes:
    """Draw the model on ``ax`` (a new figure when None), world frame, metres."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(9, 6))
    xy = {**{n: f.xy for n, f in model.fixed.items()}, **model.positions}
    if springs:
        for spring in model.springs():
            if not all(e in xy for e in spring.ends):
                continue
            pts = np.array([xy[e] for e in spring.ends])
            ax.plot(pts[:, 0], pts[:, 1], **SPRING_STYLE[spring.kind])
    for name, point in model.fixed.items():
        ax.plot(point.x, point.y, ls="none", **FIXED_STYLE[point.kind])
        if labels and name != START_ANCHOR:
            ax.annotate(name, (point.x, point.y), fontsize=6, color="dimgray", xytext=(3, -7),
                        textcoords="offset points")
    observed = [n for n in model.positions if model.is_observed(n)]
    for name, pos in model.positions.items():
        if is_anchor(name):
            continue
        colour = "black" if name in observed else "tab:blue"
        ax.plot(*pos, "o", color=colour, ms=4)
        if labels:
            ax.annotate(name, pos, fontsize=7, color=colour, xytext=(3, 3), textcoords="offset points")
    if model.goal is not None and model.goal in model.positions:
        ax.plot(*model.positions[model.goal], "*", color="gold", mec="black", ms=16, zorder=5)
    if model.explored_centre is not None:
        ax.plot(*model.explored_centre, "x", color="tab:purple", ms=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return ax


def save_picture(model: AbstractMap, path: str | os.PathLike[str], *, title: str | None = None) -> None:
    """Draw the model to an image file."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10, 7))
    draw_abstract_map(model, ax)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=120, format=Path(path).suffix.lstrip(".").lower() or "png")
    finally:
        plt.close(fig)
