"""Pictures of trials: the path over the floor plan, and an animation of a run.

Drawing lives here, apart from the simulation; matplotlib is imported inside
the functions and always renders off-screen.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from abstract_map.files import atomic_path
from sim.experiments.walk import point_at

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from sim.experiments.trial import Frame, TrialResult
    from sim.world.data import World


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def draw_floorplan(ax: Axes, world: World, *, alpha: float = 1.0) -> None:
    """The floor plan in world coordinates (m), walls dark."""
    ax.imshow(world.floorplan.occupied, cmap="Greys", extent=world.floorplan.extent, origin="upper",
              alpha=alpha, interpolation="nearest", vmin=0, vmax=1.6)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def draw_tags(ax: Axes, world: World, read: Sequence[int] = (), goal_tags: Sequence[int] = ()) -> None:
    """Every tag as a small arrow along its facing; read tags bold, the goal's label gold."""
    for tag in world.tags.values():
        colour = "gold" if tag.id in goal_tags else ("tab:red" if tag.id in read else "silver")
        ax.arrow(tag.x, tag.y, 0.5 * np.cos(tag.theta), 0.5 * np.sin(tag.theta), width=0.08,
                 color=colour, length_includes_head=True, zorder=3)
        if tag.id in read or tag.id in goal_tags:
            ax.annotate(str(tag.id), (tag.x, tag.y), fontsize=7, xytext=(3, 3), textcoords="offset points")


def draw_path(ax: Axes, trajectory: np.ndarray, *, colour: Any = "tab:blue", label: str | None = None) -> None:
    """A trajectory (N, >=3: t, x, y, ...) with its start circled and its end crossed."""
    ax.plot(trajectory[:, 1], trajectory[:, 2], color=colour, lw=1.8, label=label, zorder=4)
    ax.plot(trajectory[0, 1], trajectory[0, 2], "o", mfc="none", mec=colour, ms=10, mew=2, zorder=5)
    ax.plot(trajectory[-1, 1], trajectory[-1, 2], "x", color=colour, ms=10, mew=2, zorder=5)


WALK_MARKS = (("near_at_m", "^", "first near the label"), ("seen_at_m", "D", "label first seen"))
"""Each walk mark (:mod:`sim.experiments.walk`): its field, its marker and its legend text."""


def draw_walk_marks(ax: Axes, trajectory: np.ndarray, distance_m: float, marks: dict[str, float | None], *,
                    colour: Any = "tab:blue") -> None:
    """Where along ``trajectory`` (N, >=3: t, x, y, ...; ``distance_m`` long) the robot first came near the
    goal's label and first saw it (``marks``: the fields of :data:`WALK_MARKS`, m walked; None: never)."""
    for field, marker, text in WALK_MARKS:
        at = marks.get(field)
        if at is None or len(trajectory) == 0:
            continue
        x, y = point_at(trajectory, distance_m, at)
        ax.plot(x, y, marker, mfc="white", mec=colour, ms=9, mew=2, zorder=6, label=f"{text}, {at:.1f} m")


def draw_places(ax: Axes, places: dict[str, tuple[float, float]], goal: str | None = None,
                *, names: bool = True) -> None:
    """Imagined places as dots (the goal as a star)."""
    for name, (x, y) in places.items():
        if name == goal:
            ax.plot(x, y, "*", color="gold", mec="black", ms=15, zorder=6)
        else:
            ax.plot(x, y, ".", color="tab:green", ms=6, zorder=5)
        if names:
            ax.annotate(name, (x, y), fontsize=6, color="darkgreen", xytext=(2, 2), textcoords="offset points")


def trajectory_picture(result: TrialResult, world: World, path: str | os.PathLike[str]) -> None:
    """Floor plan, the robot's path, the tags it read, and the final imagined places."""
    plt = _pyplot()
    fig = _trajectory_figure(plt, result, world)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)


def trajectory_image(result: TrialResult, world: World, *, dpi: int = 60) -> np.ndarray:
    """The picture of :func:`trajectory_picture` as an RGB array (rows, cols, 3) uint8."""
    plt = _pyplot()
    fig = _trajectory_figure(plt, result, world)
    fig.set_dpi(dpi)
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy()
    plt.close(fig)
    return image


def _trajectory_figure(plt: Any, result: TrialResult, world: World) -> Any:
    fig, ax = plt.subplots(figsize=(12, 7.5))
    draw_floorplan(ax, world)
    goal_tags = [t.id for t in world.label_tags(result.goal)]
    draw_tags(ax, world, read=[c.tag_id for c in result.cues], goal_tags=goal_tags)
    draw_places(ax, result.final_positions, result.goal)
    draw_path(ax, result.trajectory, label=f"robot, {result.distance_m:.1f} m")
    draw_walk_marks(ax, result.trajectory, result.distance_m,
                    {"near_at_m": result.near_at_m, "seen_at_m": result.seen_at_m})
    x0, x1, y0, y1 = world.floorplan.extent
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    verdict = "found" if result.success else f"failed: {result.reason}"
    ax.set_title(f"{world.title}: {result.goal} ({result.perception}, seed {result.seed}): {verdict}, "
                 f"{result.distance_m:.1f} m, {len(result.cues)} cues")
    ax.legend(loc="lower right")
    fig.tight_layout()
    return fig


def animation(result: TrialResult, world: World, path: str | os.PathLike[str], *, fps: int = 8) -> None:
    """An animation (GIF, or MP4 if the name ends so and ffmpeg is there) of explored map, robot and model."""
    import imageio.v2 as imageio

    plt = _pyplot()
    images = []
    fig, ax = plt.subplots(figsize=(9, 5.6), dpi=80)
    x0, x1, y0, y1 = world.floorplan.extent
    for frame in result.frames:
        ax.clear()
        draw_floorplan(ax, world, alpha=0.15)
        _draw_frame(ax, frame, result, world)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_title(f"{result.goal}: t = {frame.t_s:5.1f} s")
        fig.canvas.draw()
        images.append(np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy())
    plt.close(fig)
    if not images:
        raise ValueError("no frames were recorded: run the trial with record=True")
    with atomic_path(path) as tmp:
        imageio.mimsave(tmp, images, duration=1000 / fps, loop=0) if str(path).endswith(".gif") else \
            imageio.mimsave(tmp, images, fps=fps)


def _draw_frame(ax: Axes, frame: Frame, result: TrialResult, world: World) -> None:
    extent = result.grid_extent or world.floorplan.extent
    ax.imshow(frame.grid, cmap="gray", extent=extent, origin="upper", alpha=0.6, interpolation="nearest")
    _draw_layers(ax, frame.layers, extent)
    done = result.trajectory[result.trajectory[:, 0] <= frame.t_s]
    if len(done):
        ax.plot(done[:, 1], done[:, 2], color="tab:blue", lw=1.5)
    if frame.path is not None:
        ax.plot(frame.path[:, 0], frame.path[:, 1], color="tab:orange", lw=1, ls="--")
    draw_places(ax, frame.places, result.goal, names=False)
    ax.plot(*frame.target, "+", color="red", ms=12, mew=2)
    x, y, theta = frame.pose
    ax.plot(x, y, "o", color="tab:blue", ms=7)
    ax.arrow(x, y, 0.8 * np.cos(theta), 0.8 * np.sin(theta), width=0.08, color="tab:blue")


LAYER_COLOURS = {"swept": (0.0, 0.6, 0.9), "belief": (0.9, 0.1, 0.5)}  # RGB of each policy layer


def _draw_layers(ax: Axes, layers: dict[str, np.ndarray], extent: tuple[float, float, float, float]) -> None:
    """A policy's layers (uint8 images on the grid) as tints: swept space blue, the goal belief magenta."""
    for name, image in layers.items():
        rgba = np.zeros((*image.shape, 4))
        rgba[..., :3] = LAYER_COLOURS.get(name, (0.5, 0.5, 0.0))
        rgba[..., 3] = (image / 255.0) ** 0.5 * 0.8  # square root: the belief's tail stays visible
        ax.imshow(rgba, extent=extent, origin="upper", interpolation="nearest", zorder=2)
