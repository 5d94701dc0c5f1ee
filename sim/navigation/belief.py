"""Negative information: where the goal's label has been looked for, and where it may still be.

Two grids over the robot's occupancy grid (same cells, world frame, metres):

- :class:`SweptSpace`: for each cell, whether a label hung there (on a wall
  the robot has mapped) would already have been read: within the reading range
  of a camera position the robot passed, inside the reading cone about the
  wall's normal, with a clear line of sight over the occupancy grid. This is
  the perception's reading rule (see :mod:`sim.world.visibility`) asked of the
  robot's own map, with margins so that "swept" means "would have been read".
- :func:`goal_belief`: a distribution over the cell holding the goal's label.
  Its prior is the abstract map's: a Gaussian about the goal's imagined
  position, its spread growing with how far that position is extrapolated from
  anything observed, mixed with Gaussians about the labels read of the goal's
  siblings (places of one area hang together). That is a prior over where the
  place is; its label hangs on a wall within about ``label_offset_m`` of it, so
  each place's share goes to the wall near it, shared by wall chance (1 mapped
  wall, 0 mapped free, ``unknown_wall_prob`` unseen). Swept cells are
  multiplied by the chance a label there was missed.

See ``docs/method-notes.md`` (negative information) for the equations.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from abstract_map.clauses import NAMED_BY
from sim.mapping.occupancy import OccupancyGrid


@dataclass(frozen=True)
class BeliefParams:
    """The reading rule the sweep assumes, and the goal belief's prior."""

    read_range_m: float = 3.5  # m; the perception reads to 4 m, the sweep claims only this much (camera margin)
    read_min_m: float = 1.0  # m; the camera misses tags closer than ~1 m below it, so nearer is not swept
    cone_half_angle_deg: float = 40.0  # deg about the wall normal; the perception's 45 less a margin
    los_skip_m: float = 0.09  # m; the last part of a sight line (inside the label's own wall cell) is not checked
    detect_prob: float = 0.95  # chance a label in swept space would have been read (camera misses, odd walls)
    normal_smoothing_m: float = 0.2  # m, std of the smoothing of the wall-orientation (structure) tensor
    corner_coherence: float = 0.3  # below this wall-orientation coherence (corners, specks) any view angle counts
    unknown_wall_prob: float = 0.05  # chance an unseen cell holds a label-bearing wall face, against a mapped face's 1
    sigma_min_m: float = 5.0  # m, spread of the goal's prior even with evidence right beside it, for a goal a
    # phrase read names (its figure or a referent): held out on development buildings 12-35 the model places such
    # a place 7.4 m rms from its label, sqrt(7.4^2 / 2 - label_offset_m^2) = 4.9 m a side
    # (scripts/placement_by_cue.py)
    sigma_min_arrow_m: float = 5.0  # m, the same for a goal only arrows read name. Measured there: 12.2 m rms,
    # 8.4 m a side; with it and 9.9 m below, development 24-63 gained +0.013 +- 0.005 SPL over 300 trials, but
    # fresh development buildings 64-83 lost -0.018 +- 0.007 over 100 and the test split tied (docs/method-notes.md,
    # "The prior's floor by how the goal is named"), so every goal keeps the phrases' 5 m
    sigma_min_hierarchy_m: float = 5.0  # m, the same for a goal no cue read names (the hierarchy alone places
    # it): 14.2 m rms there, 9.9 m a side; kept at 5 m for the same reason
    sigma_per_m: float = 0.35  # m of spread per m between the imagined goal and the nearest observed anchor
    label_offset_m: float = 2.0  # m, a place's label hangs about this far from the place (level-1 label length):
    # the spread of the label about its place, over the wall there. It enters twice, in goal_sigma's spread and in
    # labels_near_places' kernel; counted once the prior is a little narrower and walked no better on development
    # buildings 64-103 (-0.003 +- 0.005 SPL; docs/method-notes.md, "The label's offset counted once")
    prior_misses: float = 3.0  # how many of the model's misses (below) the spread from ``sigma_min_m`` and
    # ``sigma_per_m`` counts as: a few labels read decide how far the model is trusted in this building
    tail_weight: float = 0.3  # share of the prior in a wide tail: the model may be wrong (a sign misread, a guess)
    tail_scale: float = 3.0  # the tail's spread, in multiples of sigma
    family_sigma_m: float = 6.5  # m, spread of a place's label about a sibling's (same parent area) label: the
    # per-axis rms of sibling label distances on development buildings 0-99 is 6.6-6.8 m
    # (scripts/sibling_spread.py)
    family_front_m: float = 0.5  # m in front of a label (along its facing) where the way it faces begins: the wall
    # line's half width in "Labels of other areas" (docs/method-notes.md)
    family_across_m: float = 4.0  # m in front of a label where the way it faces ends: past the widest corridor (3 m)
    # and a label on its far wall; beyond lie halls and the next block, which this leaves alone
    family_behind_m: float = 6.0  # m behind a label (into its own block) counted as its side when the building's
    # pairs are counted (:func:`across_ratio`): the measurement's nearer bin behind, a room's depth
    family_along_m: float = 10.0  # m along a label's wall within which a pair of labels read is counted at all:
    # where one area's share of the labels on a wall line falls to about a half (same measurement)
    family_pairs: float = 4.0  # pseudo-pairs on each side (half of them of one area) before the building's own
    # pairs: a few pairs of labels read decide how a building's areas lie (as ``prior_misses`` for the model)

    def floor_m(self, placed_by: str) -> float:
        """The least spread (m) of the prior of a goal the cues read name ``placed_by`` (one of
        :data:`abstract_map.clauses.NAMED_BY`)."""
        floors = {"phrase": self.sigma_min_m, "arrow": self.sigma_min_arrow_m, "hierarchy": self.sigma_min_hierarchy_m}
        if placed_by not in floors:
            raise ValueError(f"placed_by must be one of {NAMED_BY}, got {placed_by!r}")
        return floors[placed_by]


@dataclass(frozen=True)
class Sweep:
    """One look: the cells newly swept from a camera position."""

    camera_xy: tuple[float, float]  # m
    cells: np.ndarray  # (N, 2) row, col


def cell_window(rc: np.ndarray, reach: int, shape: tuple[int, int]) -> tuple[int, int, int, int]:
    """Row and column bounds (r0, r1, c0, c1) of the cells within ``reach`` cells of ``rc``, clipped to ``shape``."""
    rows, cols = shape
    return (max(0, int(rc[0]) - reach), min(rows, int(rc[0]) + reach + 1),
            max(0, int(rc[1]) - reach), min(cols, int(rc[1]) + reach + 1))


def wall_axes(occupied: np.ndarray, smoothing_cells: float) -> tuple[np.ndarray, np.ndarray]:
    """Per cell, the unsigned wall-normal angle (rad) and its coherence in [0, 1] from the structure tensor.

    The structure tensor of the occupied mask (gradient outer products, smoothed)
    has its dominant eigenvector across the wall; coherence (l1 - l2) / (l1 + l2)
    is ~1 along straight walls and ~0 at corners and isolated specks.
    """
    occ = occupied.astype(np.float32)
    gy = ndimage.sobel(occ, axis=0)  # rows grow downwards (towards -y)
    gx = ndimage.sobel(occ, axis=1)
    gy = -gy
    s = max(smoothing_cells, 0.5)
    jxx = ndimage.gaussian_filter(gx * gx, s)
    jyy = ndimage.gaussian_filter(gy * gy, s)
    jxy = ndimage.gaussian_filter(gx * gy, s)
    angle = 0.5 * np.arctan2(2.0 * jxy, jxx - jyy)
    trace = jxx + jyy
    coherence = np.sqrt((jxx - jyy) ** 2 + 4.0 * jxy ** 2) / np.maximum(trace, 1e-9)
    coherence[trace < 1e-6] = 0.0
    return angle, coherence


def sight_clear(occupied: np.ndarray, grid: OccupancyGrid, origin_xy: np.ndarray, ends_xy: np.ndarray,
                skip_m: float, step_cells: float = 0.5) -> np.ndarray:
    """For each end (N, 2 m), whether the segment from ``origin_xy`` (one point, or one per end) to it, less
    its last ``skip_m``, misses every cell set in ``occupied`` (sampled every ``step_cells`` cells; cells off
    the grid count as clear)."""
    ends = np.atleast_2d(np.asarray(ends_xy, dtype=float))
    if len(ends) == 0:
        return np.zeros(0, dtype=bool)
    origins = np.broadcast_to(np.asarray(origin_xy, dtype=float), ends.shape)
    res = grid.resolution
    x0, y0 = grid.origin
    rows, cols = occupied.shape
    # Continuous cell coordinates: col = floor(u), row = rows - 1 - floor(v).
    u0, v0 = (origins[:, 0] - x0) / res, (origins[:, 1] - y0) / res
    du, dv = (ends[:, 0] - x0) / res - u0, (ends[:, 1] - y0) / res - v0
    length = np.hypot(du, dv)
    n = max(2, int(math.ceil(float(length.max()) / step_cells)) + 1)
    s = np.linspace(0.0, 1.0, n, dtype=np.float32)[None, :]
    use = s <= (np.maximum(length - skip_m / res, 0.0) / np.maximum(length, 1e-9))[:, None]
    col = np.clip(np.floor(u0[:, None] + s * du[:, None]).astype(np.intp), 0, cols - 1)
    row = np.clip(rows - 1 - np.floor(v0[:, None] + s * dv[:, None]).astype(np.intp), 0, rows - 1)
    return ~np.any(occupied[row, col] & use, axis=1)


def face_normals(occupied: np.ndarray, smoothing_cells: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per cell: the face normal (nx, ny) along the wall's axis towards its open side, whether the cell is a
    one-sided face (1.0: open on one side of the axis only, 0.0: both or neither), and from
    :func:`wall_axes` the unsigned axis angle (rad) and its coherence."""
    axis, coherence = wall_axes(occupied, smoothing_cells)
    ux, uy = np.cos(axis), np.sin(axis)
    rows, cols = occupied.shape
    rr, cc = np.mgrid[0:rows, 0:cols]
    dr, dc = -np.rint(uy).astype(np.intp), np.rint(ux).astype(np.intp)
    ahead = ~occupied[np.clip(rr + dr, 0, rows - 1), np.clip(cc + dc, 0, cols - 1)]
    behind = ~occupied[np.clip(rr - dr, 0, rows - 1), np.clip(cc - dc, 0, cols - 1)]
    sign = np.where(ahead & ~behind, 1.0, np.where(behind & ~ahead, -1.0, 0.0))
    return sign * ux, sign * uy, np.abs(sign), axis, coherence


def in_cone(site_xy: np.ndarray, camera_xy: np.ndarray, axis: np.ndarray, coherence: np.ndarray,
            params: BeliefParams, normal: np.ndarray | None = None, sided: np.ndarray | None = None) -> np.ndarray:
    """Whether each camera-site pair lies inside the reading cone about the site's wall normal.

    Where the wall has one mapped face (``sided`` >= 0.5) the camera must be in
    front of it (``normal``, (..., 2), points to the free side); otherwise
    either side of the unsigned ``axis`` counts; at corners (low coherence) any.
    """
    d = np.asarray(camera_xy, dtype=float) - np.asarray(site_xy, dtype=float)
    distance = np.maximum(np.hypot(d[..., 0], d[..., 1]), 1e-9)
    cos_min = math.cos(math.radians(params.cone_half_angle_deg))
    unsigned = np.abs(d[..., 0] * np.cos(axis) + d[..., 1] * np.sin(axis)) / distance
    ok = (unsigned >= cos_min) | (coherence < params.corner_coherence)
    if normal is not None and sided is not None:
        signed = (d[..., 0] * normal[..., 0] + d[..., 1] * normal[..., 1]) / distance
        ok = np.where(sided >= 0.5, signed >= cos_min, ok)
    return ok


class SweptSpace:
    """Cells of the occupancy grid where a label would already have been read (1.0) or not (0.0)."""

    def __init__(self, grid: OccupancyGrid, params: BeliefParams = BeliefParams()) -> None:
        self.params = params
        self.swept = np.zeros(grid.shape, dtype=bool)
        self.looks = 0

    def sweep(self, grid: OccupancyGrid, camera_xy: tuple[float, float] | np.ndarray) -> Sweep:
        """Mark the mapped wall cells a label on which would be read from ``camera_xy`` (m) now."""
        prm = self.params
        camera = np.asarray(camera_xy, dtype=float)
        res = grid.resolution
        occupied = grid.occupied_mask()
        rc = grid.world_to_cell(camera)[0]
        reach = int(math.ceil(prm.read_range_m / res)) + 2
        rows, cols = grid.shape
        r0, r1, c0, c1 = cell_window(rc, reach, grid.shape)
        self.looks += 1
        window = occupied[r0:r1, c0:c1] & ~self.swept[r0:r1, c0:c1]
        cand = np.argwhere(window) + np.array([r0, c0])
        if len(cand) == 0:
            return Sweep((float(camera[0]), float(camera[1])), np.zeros((0, 2), dtype=int))
        xy = grid.cell_to_world(cand)
        distance = np.hypot(*(xy - camera).T)
        near = (distance <= prm.read_range_m) & (distance >= prm.read_min_m)
        cand, xy = cand[near], xy[near]
        # Wall orientation from a margin around the window, so walls at its edge are judged whole.
        m = int(math.ceil(3 * prm.normal_smoothing_m / res)) + 1
        q0, q1, p0, p1 = max(0, r0 - m), min(rows, r1 + m), max(0, c0 - m), min(cols, c1 + m)
        nx, ny, sided, axis, coherence = face_normals(occupied[q0:q1, p0:p1], prm.normal_smoothing_m / res)
        i, j = (cand - np.array([q0, p0])).T
        ok = in_cone(xy, camera, axis[i, j], coherence[i, j], prm, np.stack([nx[i, j], ny[i, j]], axis=-1),
                     sided[i, j])
        cand, xy = cand[ok], xy[ok]
        clear = sight_clear(occupied, grid, camera, xy, prm.los_skip_m)
        cells = cand[clear]
        self.swept[cells[:, 0], cells[:, 1]] = True
        return Sweep((float(camera[0]), float(camera[1])), cells)


@dataclass(frozen=True)
class GoalPrior:
    """Where the abstract map puts the goal, how far it is trusted there, and the labels of the goal's siblings."""

    centre: np.ndarray  # (2,) m, the goal's imagined position
    sigma_m: float  # m, spread about it (:func:`goal_sigma`)
    family_xy: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (K, 2) m, labels read of places
    # sharing the goal's parent area (none when that parent is the hierarchy's root)
    family_facing: np.ndarray = field(default_factory=lambda: np.zeros(0))  # (K,) rad, the way each of those labels
    # faces (is read from); empty: not known, each sibling's component even all round
    family_across: float = 1.0  # density of a sibling's component across the way its label faces against beside
    # and behind it (:func:`across_ratio`, learned from the labels read in this building); 1: even all round


@dataclass(frozen=True)
class MixedPrior:
    """Goal priors held at once, each with the chance it is the right one: ``parts`` of (weight, prior), the
    weights summing to 1. Each part is spread over the grid as a whole before it is weighted, so a part that
    lies even over the building counts as much as one gathered in a corner. ``centre`` and ``sigma_m`` are the
    first part's (the abstract map's own)."""

    parts: tuple[tuple[float, GoalPrior], ...]

    @property
    def centre(self) -> np.ndarray:
        return self.parts[0][1].centre

    @property
    def sigma_m(self) -> float:
        return self.parts[0][1].sigma_m


def prior_components(prior: GoalPrior, params: BeliefParams) -> list[tuple[float, np.ndarray, float]]:
    """The prior's core as Gaussian components (weight, centre m, spread m), weights summing to 1.

    With no sibling label it is the imagined goal alone. With labels ``f_k`` of ``K`` siblings read, it is a
    mixture: the imagined goal ``N(c, sigma^2)`` with weight ``a = s_f^2 / (sigma^2 + s_f^2)``, and each
    sibling's ``N(f_k, s_f^2)`` (``s_f``: ``family_sigma_m``) with ``(1 - a) / K``. Each estimate counts by
    its precision: a model trusted to a few metres keeps most of the prior; one that has missed by tens of
    metres in this building hands it to the area where the siblings were read. A mixture, not a product:
    either may be wrong by more than its spread says (the model's misses are heavy-tailed)."""
    centre, sigma = np.asarray(prior.centre, dtype=float), float(prior.sigma_m)
    family = np.asarray(prior.family_xy, dtype=float).reshape(-1, 2)
    if len(family) == 0:
        return [(1.0, centre, sigma)]
    sf2, s2 = params.family_sigma_m ** 2, sigma ** 2
    own = sf2 / (s2 + sf2)
    return [(own, centre, sigma)] + [((1.0 - own) / len(family), f, params.family_sigma_m) for f in family]


@dataclass(frozen=True)
class Belief:
    """Where the goal's label may be: a distribution over the occupancy grid's cells."""

    mass: np.ndarray  # (rows, cols) float, sums to 1 (all zero when nothing remains)
    remaining: float  # the prior's probability of a label on the grid not yet ruled out, in [0, 1]
    centre: tuple[float, float]  # m, the prior's mean (the goal's imagined position)
    sigma_m: float  # m, the prior's spread


def goal_sigma(goal_xy: np.ndarray, anchors_xy: np.ndarray, params: BeliefParams,
               misses_m: Sequence[float] = (), placed_by: str = "phrase") -> float:
    """Spread (m) of the goal's prior.

    Before any miss, the label offset in quadrature with a share of the distance to the nearest observed anchor
    (a tag read, or the start), at least the floor for how the cues read name the goal (``placed_by``:
    :meth:`BeliefParams.floor_m`; a phrase places a place about twice as well as the hierarchy alone, an arrow
    between the two). ``misses_m`` are the model's own misses in this
    building (m): how far each label read lay from where the model imagined its place just before. They
    replace that guess as they come: with ``n`` misses ``e_i`` and the guess counted as ``prior_misses`` of
    them, ``sigma^2 = (n0 guess^2 + sum e_i^2 / 2) / (n0 + n)`` (a miss in the plane has mean square
    ``2 sigma^2``)."""
    anchors = np.atleast_2d(np.asarray(anchors_xy, dtype=float))
    nearest = float(np.min(np.hypot(*(anchors - goal_xy).T))) if anchors.size else 0.0
    spread = max(params.floor_m(placed_by), params.sigma_per_m * nearest)
    guess = math.hypot(spread, params.label_offset_m)
    n0, misses = params.prior_misses, np.asarray(misses_m, dtype=float)
    return math.sqrt((n0 * guess ** 2 + float(np.sum(misses ** 2)) / 2) / (n0 + len(misses)))


def wall_chance(occupied: np.ndarray, free: np.ndarray, params: BeliefParams) -> np.ndarray:
    """Per cell, the chance it carries a label-bearing wall face: 1 mapped wall, 0 mapped free,
    ``unknown_wall_prob`` unseen."""
    return np.where(occupied, 1.0, np.where(free, 0.0, params.unknown_wall_prob))


def block_mean(a: np.ndarray, k: int) -> np.ndarray:
    """Means over ``k`` x ``k`` blocks of ``a`` (the last blocks padded with zeros)."""
    rows, cols = -(-a.shape[0] // k) * k, -(-a.shape[1] // k) * k
    padded = np.zeros((rows, cols))
    padded[:a.shape[0], :a.shape[1]] = a
    return padded.reshape(rows // k, k, cols // k, k).mean(axis=(1, 3))


def labels_near_places(density: np.ndarray, wall: np.ndarray, reach_cells: float) -> np.ndarray:
    """Per cell, the chance the label hangs there, given ``density`` (per cell) over where its place is and
    each cell's ``wall`` chance: each place's share goes to the wall about it, in proportion to wall chance
    times a Gaussian of ``reach_cells`` (cells) about the place,
    ``w(s) sum_p density(p) K(s - p) / sum_s' w(s') K(s' - p)``.

    So where all about a place is unseen, its share stays in that unseen space, however much mapped wall
    lies further off. Worked on blocks a quarter of the reach across (two Gaussian filters), exact to the
    block size; places with no wall within four reaches pass on nothing."""
    k = max(1, int(reach_cells / 4))
    reach = reach_cells / k
    near = ndimage.gaussian_filter(block_mean(wall, k), reach, mode="constant")
    share = np.divide(block_mean(density, k), near, out=np.zeros(near.shape), where=near > 1e-9)
    spread = ndimage.gaussian_filter(share, reach, mode="constant")
    return wall * np.repeat(np.repeat(spread, k, axis=0), k, axis=1)[:wall.shape[0], :wall.shape[1]]


def place_density(grid: OccupancyGrid, prior: GoalPrior, params: BeliefParams) -> np.ndarray:
    """Per grid cell, the place's prior density (1 / m^2): :func:`prior_components` mixed with a wide tail about
    the imagined goal (``tail_weight``, ``tail_scale`` times its spread)."""
    centre = np.asarray(prior.centre, dtype=float)
    xy_col, xy_row = grid.cell_axes()
    components = [((1.0 - params.tail_weight) * w, c, s) for w, c, s in prior_components(prior, params)]
    components.append((params.tail_weight, centre, params.tail_scale * prior.sigma_m))
    facing = np.asarray(prior.family_facing, dtype=float).ravel()
    siblings = len(np.asarray(prior.family_xy).reshape(-1, 2))
    if len(facing) not in (0, siblings):
        raise ValueError(f"family_facing must give one facing per sibling label ({siblings}) or none, "
                         f"got {len(facing)}")
    density = np.zeros(grid.shape)
    for k, (weight, mean, spread) in enumerate(components):
        gx = np.exp(-0.5 * ((xy_col - mean[0]) / spread) ** 2)
        gy = np.exp(-0.5 * ((xy_row - mean[1]) / spread) ** 2)
        part = weight / spread ** 2 * np.outer(gy, gx)
        if 1 <= k <= len(facing) and prior.family_across < 1.0:  # a sibling's component (after the goal's)
            part = sided(part, xy_col - mean[0], xy_row - mean[1], facing[k - 1], prior.family_across, params)
        density += part
    return density


def sided(part: np.ndarray, dx: np.ndarray, dy: np.ndarray, facing: float, across: float,
          params: BeliefParams) -> np.ndarray:
    """``part`` (rows, cols) with the cells across the way a label facing ``facing`` (rad) looks onto (from
    ``family_front_m`` to ``family_across_m`` in front of it) scaled by ``across``, then scaled back to ``part``'s
    sum. ``dx`` (cols,) and ``dy`` (rows,) are the cells' offsets (m) from the label."""
    ahead = dx[None, :] * math.cos(facing) + dy[:, None] * math.sin(facing)
    shaped = np.where((ahead > params.family_front_m) & (ahead <= params.family_across_m), across * part, part)
    total = float(shaped.sum())
    return shaped * (float(part.sum()) / total) if total > 0 else part


def label_offsets(xy: np.ndarray, facing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For labels at ``xy`` ((K, 2) m) facing ``facing`` ((K,) rad), per ordered pair ``[i, j]``: how far label
    ``j`` lies in front of label ``i`` (m, along ``i``'s facing; negative: behind) and how far along ``i``'s
    wall (m, unsigned)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    d = xy[None, :, :] - xy[:, None, :]  # [i, j]: from label i to label j
    c, s = np.cos(facing)[:, None], np.sin(facing)[:, None]
    return d[..., 0] * c + d[..., 1] * s, np.abs(-d[..., 0] * s + d[..., 1] * c)


def across_ratio(xy: np.ndarray, facing: np.ndarray, area: Sequence[str], params: BeliefParams) -> float:
    """How likely a label across the way another faces is of the same area, against one beside or behind it,
    from the ``K`` labels read so far in this building (``xy`` (K, 2) m, ``facing`` (K,) rad, ``area``: each
    one's parent area). Over ordered pairs within ``family_along_m`` along the first's wall: the share of one
    area across (``family_front_m`` to ``family_across_m`` in front) over the share beside or behind (to
    ``family_behind_m`` behind), each share with ``family_pairs`` pseudo-pairs half of one area, at most 1.
    Where areas are blocks between corridors (the generator's), the way a label faces holds other areas'
    labels and the ratio falls to about a tenth; where an area lines both sides of a path (the zoo's), it
    stays 1."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    ahead, along = label_offsets(xy, facing)
    names = np.asarray(area, dtype=object)
    same = names[:, None] == names[None, :]
    counted = (along <= params.family_along_m) & ~np.eye(len(xy), dtype=bool)
    side = counted & (ahead >= -params.family_behind_m) & (ahead <= params.family_front_m)
    across = counted & (ahead > params.family_front_m) & (ahead <= params.family_across_m)
    n0 = params.family_pairs
    share_side = (float((same & side).sum()) + n0 / 2) / (float(side.sum()) + n0)
    share_across = (float((same & across).sum()) + n0 / 2) / (float(across.sum()) + n0)
    return min(1.0, share_across / share_side)


def goal_belief(grid: OccupancyGrid, swept: np.ndarray, prior: GoalPrior | MixedPrior, params: BeliefParams,
                evidence: np.ndarray | None = None) -> Belief:
    """Posterior over the label's cell: the place's prior x evidence, handed to the wall near each place
    (:func:`labels_near_places`), x (1 - detect_prob on swept cells).

    The place's prior is :func:`place_density` (the imagined goal mixed with
    its siblings' labels and a wide tail), or for a :class:`MixedPrior` its
    parts', each made to sum to 1 over the grid and weighted. ``evidence`` (the grid's
    shape, e.g. :func:`sim.navigation.routes.route_likelihood` of the arrows
    read) multiplies it.

    ``remaining`` is the posterior's normaliser against the prior's (both with
    each cell's wall chance): the share of the prior on wall not yet swept, near
    1 when nothing near the goal has been looked at, near 0 when it all has; for
    a :class:`MixedPrior`, of its first part's (the model's own: whether the
    label is where the model imagines it).
    """
    centre = np.asarray(prior.centre, dtype=float)
    parts = ((1.0, prior),) if isinstance(prior, GoalPrior) else prior.parts
    wall = wall_chance(grid.occupied_mask(), grid.free_mask(), params)
    unswept = np.where(swept, 1.0 - params.detect_prob, 1.0)
    shares = []  # per part: its weighted prior on the walls, and that share not yet swept
    for weight, part in parts:
        density = place_density(grid, part, params) if weight > 0 else np.zeros(grid.shape)
        if len(parts) > 1:
            total = float(density.sum())
            density = weight / total * density if total > 0 else np.zeros(grid.shape)
        if evidence is not None:
            density = density * evidence
        weighted = labels_near_places(density, wall, params.label_offset_m / grid.resolution)
        shares.append((weighted, weighted * unswept))
    posterior = functools.reduce(np.add, (p for _, p in shares))
    total = float(posterior.sum())
    mass = posterior / total if total > 0 else posterior
    own_reference, own_left = float(shares[0][0].sum()), float(shares[0][1].sum())
    remaining = min(1.0, own_left / own_reference) if own_reference > 0 else 0.0
    return Belief(mass.astype(np.float32), remaining, (float(centre[0]), float(centre[1])),
                  float(prior.sigma_m))


def cue_mass(grid: OccupancyGrid, swept: np.ndarray, robot_xy: np.ndarray, radius_m: float,
             params: BeliefParams) -> np.ndarray:
    """Unswept wall (by wall chance) within ``radius_m`` (m) of the robot, summing to 1 (all zero if none):
    where any cue, a sign or a label, may still be read."""
    rows, cols = grid.shape
    rc = grid.world_to_cell(np.asarray(robot_xy, dtype=float))[0]
    reach = int(math.ceil(radius_m / grid.resolution))
    out = np.zeros(grid.shape, dtype=np.float64)
    r0, r1, c0, c1 = cell_window(rc, reach, grid.shape)
    if r0 >= r1 or c0 >= c1:
        return out
    rr, cc = np.mgrid[r0:r1, c0:c1]
    near = np.hypot(rr - rc[0], cc - rc[1]) <= reach
    occ, free = grid.occupied_mask()[r0:r1, c0:c1], grid.free_mask()[r0:r1, c0:c1]
    wall = wall_chance(occ, free, params)
    window = near * wall * np.where(swept[r0:r1, c0:c1], 1.0 - params.detect_prob, 1.0)
    total = window.sum()
    if total > 0:
        out[r0:r1, c0:c1] = window / total
    return out
