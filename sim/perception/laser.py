"""A 2D laser scanner as a pure function of a pose and a ray caster.

Frames: world frame, metres, angles in radians counter-clockwise from +x.
Beam angles are in the robot frame (0 = straight ahead). The ray caster is
passed in, so the simulator can back it with pybullet while tests and fast
planning checks use :func:`grid_caster` over a boolean occupancy image.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sim.world.pose import check_pose

Cast = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""``cast(origins (N, 2), ends (N, 2)) -> hit fractions (N,)`` in [0, 1]; 1.0 = no hit."""

_MAX_SAMPLES_PER_CHUNK = 2_000_000  # bounds the memory of one ray-march batch


@dataclass(frozen=True)
class LaserParams:
    """A planar laser scanner mounted at the robot's centre."""

    max_range_m: float = 8.0  # m; beams that hit nothing report exactly this
    fov_deg: float = 180.0  # deg, centred on the robot's heading; up to 360
    n_beams: int = 181
    height_m: float = 0.3  # m above the floor (used by 3D ray casters)
    noise_std_m: float = 0.0  # m, std of Gaussian noise added to beams that hit

    def __post_init__(self) -> None:
        if not (math.isfinite(self.max_range_m) and self.max_range_m > 0):
            raise ValueError(f"LaserParams.max_range_m must be finite and > 0, got {self.max_range_m}")
        if not (0 < self.fov_deg <= 360):
            raise ValueError(f"LaserParams.fov_deg must be in (0, 360], got {self.fov_deg}")
        if self.n_beams < 1:
            raise ValueError(f"LaserParams.n_beams must be >= 1, got {self.n_beams}")
        if not (math.isfinite(self.noise_std_m) and self.noise_std_m >= 0):
            raise ValueError(f"LaserParams.noise_std_m must be finite and >= 0, got {self.noise_std_m}")


def laser_angles(params: LaserParams = LaserParams()) -> np.ndarray:
    """Beam angles (rad, robot frame, ascending, i.e. right to left), shape (n_beams,)."""
    half = math.radians(params.fov_deg) / 2.0
    if params.n_beams == 1:
        return np.zeros(1)
    if params.fov_deg >= 360.0:
        return np.linspace(-math.pi, math.pi, params.n_beams, endpoint=False)
    return np.linspace(-half, half, params.n_beams)


def scan(
    pose: tuple[float, float, float] | np.ndarray,
    cast: Cast,
    params: LaserParams = LaserParams(),
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """Ranges (m) of every beam of :func:`laser_angles` from ``pose`` (x m, y m, theta rad).

    Beams that hit nothing report exactly ``params.max_range_m``. When
    ``params.noise_std_m > 0`` the hits get Gaussian noise from ``rng``
    (required then), clipped to [0, max_range_m].
    """
    x, y, theta = check_pose(pose)
    if params.noise_std_m > 0 and rng is None:
        raise ValueError("scan: rng is required when params.noise_std_m > 0")
    world_angles = theta + laser_angles(params)
    origins = np.tile([x, y], (world_angles.size, 1))
    ends = origins + params.max_range_m * np.stack([np.cos(world_angles), np.sin(world_angles)], axis=1)
    fractions = np.asarray(cast(origins, ends), dtype=float).ravel()
    if fractions.shape != world_angles.shape or not np.all(np.isfinite(fractions)):
        raise ValueError(f"scan: cast returned {fractions.shape} values (or non-finite ones); "
                         f"expected {world_angles.size} finite fractions")
    ranges = np.clip(fractions, 0.0, 1.0) * params.max_range_m
    if params.noise_std_m > 0 and rng is not None:
        hit = fractions < 1.0
        noisy = ranges[hit] + rng.normal(0.0, params.noise_std_m, size=int(hit.sum()))
        ranges[hit] = np.clip(noisy, 0.0, params.max_range_m)
    return ranges


def grid_caster(
    occupied: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    step_fraction: float = 0.5,
) -> Cast:
    """A ray caster over a boolean occupancy image (row 0 = top, like :class:`sim.world.data.Floorplan`).

    ``origin`` is the world position (m) of the image's bottom-left corner and
    ``resolution`` the cell edge (m). Rays are marched in steps of
    ``step_fraction * resolution``; a hit is placed where the ray enters the
    first occupied cell it samples. Cells outside the image are free. Rays
    that start inside an occupied cell do not hit it (as with a physics ray
    test), but do hit the next occupied cell they sample after leaving it.
    """
    occ = np.asarray(occupied, dtype=bool)
    if occ.ndim != 2:
        raise ValueError(f"grid_caster: occupied must be a 2D bool image, got shape {occ.shape}")
    if not (math.isfinite(resolution) and resolution > 0):
        raise ValueError(f"grid_caster: resolution must be finite and > 0, got {resolution}")
    if not (0 < step_fraction <= 1):
        raise ValueError(f"grid_caster: step_fraction must be in (0, 1], got {step_fraction}")
    x0, y0 = float(origin[0]), float(origin[1])
    rows, cols = occ.shape
    step = step_fraction * resolution

    def cast(origins: np.ndarray, ends: np.ndarray) -> np.ndarray:
        o = np.atleast_2d(np.asarray(origins, dtype=float))
        e = np.atleast_2d(np.asarray(ends, dtype=float))
        if o.shape != e.shape or o.shape[1] != 2:
            raise ValueError(f"cast: origins {o.shape} and ends {e.shape} must both be (N, 2)")
        if not (np.all(np.isfinite(o)) and np.all(np.isfinite(e))):
            raise ValueError("cast: origins and ends must be finite")
        out = np.ones(len(o))
        lengths = np.hypot(*(e - o).T)
        n_steps = np.ceil(lengths / step).astype(int)
        chunk = max(1, _MAX_SAMPLES_PER_CHUNK // max(1, int(n_steps.max(initial=0)) + 1))
        for lo in range(0, len(o), chunk):
            sl = slice(lo, lo + chunk)
            out[sl] = _march(o[sl], e[sl], lengths[sl], n_steps[sl])
        return out

    def _march(o: np.ndarray, e: np.ndarray, lengths: np.ndarray, n_steps: np.ndarray) -> np.ndarray:
        k = int(n_steps.max(initial=0))
        result = np.ones(len(o))
        if k == 0:
            return result
        # Distances along each ray: step, 2 step, ..., capped at the ray's length.
        d = np.minimum(step * np.arange(1, k + 1)[None, :], lengths[:, None])
        safe_len = np.where(lengths > 0, lengths, 1.0)
        direction = (e - o) / safe_len[:, None]
        px = o[:, 0:1] + direction[:, 0:1] * d
        py = o[:, 1:2] + direction[:, 1:2] * d
        col = np.floor((px - x0) / resolution).astype(int)
        row_up = np.floor((py - y0) / resolution).astype(int)
        inside = (col >= 0) & (col < cols) & (row_up >= 0) & (row_up < rows)
        hits = np.zeros(d.shape, dtype=bool)
        hits[inside] = occ[rows - 1 - row_up[inside], col[inside]]
        start_col = np.floor((o[:, 0] - x0) / resolution).astype(int)
        start_row = np.floor((o[:, 1] - y0) / resolution).astype(int)
        in_start_cell = (col == start_col[:, None]) & (row_up == start_row[:, None])
        hits &= ~in_start_cell
        hits &= (lengths > 0)[:, None]
        any_hit = hits.any(axis=1)
        if not any_hit.any():
            return result
        idx = np.nonzero(any_hit)[0]
        first = hits[idx].argmax(axis=1)
        d_hit = d[idx, first]
        d_prev = np.where(first > 0, d[idx, np.maximum(first - 1, 0)], 0.0)
        # Entry into the hit cell's square by the slab method, kept within the sampled bracket.
        cx = x0 + col[idx, first] * resolution
        cy = y0 + row_up[idx, first] * resolution
        d_enter = np.maximum(_slab_entry(o[idx, 0], direction[idx, 0], cx, resolution),
                             _slab_entry(o[idx, 1], direction[idx, 1], cy, resolution))
        d_enter = np.clip(d_enter, d_prev, d_hit)
        result[idx] = np.clip(d_enter / lengths[idx], 0.0, 1.0)
        return result

    return cast


def _slab_entry(start: np.ndarray, direction: np.ndarray, lo: np.ndarray, size: float) -> np.ndarray:
    """Distance along a ray where it enters the slab [lo, lo + size] on one axis (-inf if parallel)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - start) / direction
        t2 = (lo + size - start) / direction
    entry = np.minimum(t1, t2)
    return np.where(direction == 0, -np.inf, entry)
