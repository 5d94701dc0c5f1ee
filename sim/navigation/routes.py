"""Route evidence from arrows: where a place can lie, given that a sign's arrow points along its route.

A sign's arrow points along the first leg of the shortest route from the sign
to what it names (the convention of ``worlds/README.md``, which ``world check``
tests to within 45 degrees, the reader standing 1 m in front of the sign). So
a cell ``x`` is consistent with the arrow when its shortest route from the
reader's spot ``s`` sets off along the arrow: with ``q(x)`` the point where
that route (over the robot's map: mapped walls block, unseen space is open but
dearer, ``unseen_cost`` a metre against 1 over mapped floor, :func:`route_costs`)
first leaves the circle of radius ``lead_m`` about ``s``,

    error(x) = | angle(q(x) - s) - arrow |    (the first leg's direction against the arrow)

and the likelihood of the arrow given the place at ``x`` is

    L(x) = wrong + (1 - wrong) exp(-max(error(x) - tolerance, 0) / spread)

with ``wrong`` the chance the arrow is wrong (misleading signs) or, for an
arrow naming an area that holds the place, that the area's route is not the
place's. Early on, with nothing mapped, ``L`` is a cone about the arrow; as
walls are mapped it follows corridors round corners, and an arrow pointing
away from a place behind a wall says the way round lies that way. A route
planned across unseen space may be wrong about its first leg (walls not yet
seen can turn it), so a cell whose first leg misses the arrow keeps
``exp(-detour / (unseen_detour * unseen))`` instead when that is more: how much
longer a route is that sets off along the arrow, against how much of its own
route near the reader crosses unseen space (``_unseen_way``). Lengths here are
priced as the routes are (unseen metres cost ``unseen_cost``), so the detour
allowed is ``unseen_detour / unseen_cost`` of the unseen length, and the lead and
``unseen_reach_m`` shrink by that price across unseen space.

Labels hang beside doors on the side a door is approached from, so a room's
inner walls carry only the labels of rooms reached through it. From the start
(on a corridor or in a hall), :func:`door_depth_weight` counts the doorways
(passages narrower than ``door_width_m``) a route must cross to reach the
space in front of each wall, and weights a label there by ``room_weight`` per
doorway: corridor-side walls first, through-rooms later, never never.
A wall takes the likelihoods of the space in front of it too
(:func:`walls_take_front`): no route enters a wall, but the label on it is read
from there. World frame, metres.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

from sim.mapping.occupancy import OccupancyGrid, pool_cells, unpool_cells
from sim.navigation.planner import clearance_m


@dataclass(frozen=True)
class RouteParams:
    """How arrows constrain where the goal can be."""

    cell_m: float = 0.3  # m, coarse cells for route lengths: a 1 m door stays open, a 0.2 m wall still blocks
    stand_m: float = 1.0  # m in front of the sign where a reader stands (the signage convention's reader)
    lead_m: float = 1.5  # m from the reader where a route's first leg is read off (five route cells: its
    # direction to within about 10 degrees on the 8-connected grid, and short of most corridors' first turn)
    tolerance_deg: float = 45.0  # deg a first leg may lie off its arrow (the convention's, as `world check`)
    spread_deg: float = 20.0  # deg beyond the tolerance that divide the likelihood by e: an 8-connected path
    # may take its diagonal steps first, so a first leg read off the grid can lie up to 22.5 deg off its line
    unseen_detour: float = 0.41  # share of a route's length across unseen space by which the true route may be
    # longer: round a square block rather than across its diagonal (sqrt 2 - 1); see route_likelihood
    unseen_cost: float = 1.41  # route cost per metre across unseen space against 1 over mapped free space (arrows
    # and unnamed signs): a route planned straight across a block not yet seen is in truth longer by
    # ``unseen_detour`` (round it, not across its diagonal), so routes keep to mapped floor where it serves as well.
    # Measured on development buildings, 600 trials (docs/method-notes.md, "What the robot's own map costs")
    unseen_reach_m: float = 15.0  # m from the reader within which unseen space can turn a route's first leg: the
    # walls of about one block between corridors (10-20 m in most buildings)
    wrong_prob: float = 0.1  # chance an arrow naming the goal is wrong ("misleading" signage: one in ten)
    area_wrong_prob: float = 0.35  # for an arrow naming an area holding the goal, or a sibling on a sign that does
    # not name the goal: the goal may lie off that route (a wing's arrow leads to its nearest room, a sibling's to
    # that room, not to every room of the wing). On the full plan (scripts/area_arrows.py) an area's arrow sets off
    # another way than the route to 24% of its rooms on development buildings 0-47 (the zoo: 7%), a sibling's 17%
    # (the zoo: 38%); a route read off the robot's half-mapped floor is less sure (0.2 screened, not kept)
    named_prob: float = 0.7  # chance that a sign on the goal's route names it or an area holding it: the generator's
    # complete signage names all 159 of seeds 0-4 (worlds/README.md), its sparse signage half by area only; hand-made
    # buildings name fewer (the zoo's signs list a few places each)
    junction_m: float = 2.0  # m from a sign's reader within which a route counts as passing the sign (a junction
    # of corridors up to 3 m wide)
    door_width_m: float = 1.3  # m; narrower passages are doorways (doors are ~1 m, corridors 1.8 m and wider)
    robot_radius_m: float = 0.38  # m; narrower than twice this is no passage at all (the planner's radius)
    door_penalty_m: float = 10.0  # m of route cost per metre walked through a doorway's narrows (counts doors)
    door_cost_m: float = 14.0  # m of such cost one doorway adds (measured: 1 m door, 0.2 m wall, 0.2 m cells)
    room_weight: float = 0.3  # label weight per doorway crossed: a through-room's label is rarer than a corridor's;
    # with frontiers valued by the belief behind them, development buildings 0-11 found 41 of 60 goals with 0.3
    # against 32 with 0.15 (through rooms 9 of 12 against 3)
    front_m: float = 1.2  # m; a wall is weighed by the shallowest and the likeliest space this close in front of it
    # (door depth; arrows and unnamed signs): a label on it is read from there
    evidence_every_s: float = 8.0  # s between refreshing depth and route evidence (sooner on a new arrow)
    depth_pool: int = 2  # doorways are counted on cells this many times the grid's (0.2 m: a door stays narrow)


@dataclass(frozen=True)
class Arrow:
    """One arrow read: a sign's pose and the direction it gives to a place."""

    sign_xy: tuple[float, float]  # m
    facing: float  # rad, the sign's facing (its normal, towards the reader)
    direction: float  # rad, world frame, the arrow's direction
    wrong_prob: float  # chance the arrow does not lead towards the goal


_OFFSETS = np.asarray(MCP_Geometric(np.ones((3, 3)), fully_connected=True).offsets)  # (row, col) steps, 8-connected


@dataclass
class PathSearches:
    """Path-length searches kept between calls: a search from a cell over a cost grid is run again only when
    that grid changed (walls are mapped slowly, so the coarse grids often stay the same for a while)."""

    costs: dict[str, np.ndarray] = field(default_factory=dict)  # the cost grid of each kind of search
    found: dict[tuple[str, tuple], tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    # (kind, start or starts) -> lengths and scikit-image's traceback (an index into _OFFSETS per cell)
    parents: dict[tuple[str, tuple[int, int]], np.ndarray] = field(default_factory=dict)  # worked out when asked

    def lengths(self, kind: str, costs: np.ndarray, start: tuple[int, int]) -> np.ndarray:
        """Cumulative cost (in cells of ``costs``) from ``start`` to every cell of ``costs`` (inf: cut off), by
        scikit-image's minimum-cost path, 8-connected."""
        return self.lengths_from(kind, costs, (start,))

    def lengths_from(self, kind: str, costs: np.ndarray, starts: tuple[tuple[int, int], ...]) -> np.ndarray:
        """:meth:`lengths` from the nearest of several ``starts`` (each at cost 0)."""
        known = self.costs.get(kind)
        if known is None or known.shape != costs.shape or not np.array_equal(known, costs):
            self.costs[kind] = costs.copy()
            self.found = {key: value for key, value in self.found.items() if key[0] != kind}
            self.parents = {key: value for key, value in self.parents.items() if key[0] != kind}
        key = (kind, starts[0] if len(starts) == 1 else starts)
        if key not in self.found:
            self.found[key] = MCP_Geometric(costs, fully_connected=True).find_costs(list(starts))
        return self.found[key][0]

    def tree(self, kind: str, costs: np.ndarray, start: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`lengths`, and each cell's predecessor on its shortest path from ``start`` (flat index into
        ``costs``; ``start`` and cells cut off are their own)."""
        lengths = self.lengths(kind, costs, start)
        if (kind, start) not in self.parents:
            traceback = self.found[kind, start][1]
            rows, cols = np.indices(costs.shape)
            step = _OFFSETS[np.where(traceback >= 0, traceback, 0)]
            pred = (rows - step[..., 0]) * costs.shape[1] + (cols - step[..., 1])
            own = np.arange(costs.size).reshape(costs.shape)
            self.parents[kind, start] = np.where((traceback >= 0) & np.isfinite(lengths), pred, own).ravel()
        return lengths, self.parents[kind, start]


def route_cells(grid: OccupancyGrid, params: RouteParams) -> tuple[int, np.ndarray]:
    """The route cells: how many grid cells a side each pools (``cell_m``), and which are blocked (any mapped
    obstacle in it)."""
    pool = max(1, round(params.cell_m / grid.resolution))
    return pool, pool_cells(grid.occupied_mask(), pool, False, np.any)


def unseen_cells(grid: OccupancyGrid, pool: int) -> np.ndarray:
    """The route cells (``grid``'s cells pooled ``pool`` x ``pool``) mostly unseen: bool."""
    return pool_cells(grid.unknown_mask().astype(np.float32), pool, np.float32(1.0), np.mean) > 0.5


def route_costs(blocked: np.ndarray, unseen: np.ndarray, params: RouteParams) -> np.ndarray:
    """Per route cell, what a route pays to cross it: inf through a wall, ``unseen_cost`` across unseen space,
    1 over mapped free space."""
    return np.where(blocked, np.inf, np.where(unseen, params.unseen_cost, 1.0))


def open_cell(grid: OccupancyGrid, pool: int, blocked: np.ndarray, xy: np.ndarray) -> tuple[int, int] | None:
    """The open cell of ``blocked`` (``grid``'s cells pooled ``pool`` x ``pool``) nearest to ``xy`` (m), or None
    when it has none."""
    rc = grid.world_to_cell(xy)[0] // pool
    rows, cols = blocked.shape
    rc = np.clip(rc, 0, [rows - 1, cols - 1])
    if not blocked[rc[0], rc[1]]:
        return int(rc[0]), int(rc[1])
    _, (ir, ic) = ndimage.distance_transform_edt(blocked, return_indices=True)
    r, c = int(ir[rc[0], rc[1]]), int(ic[rc[0], rc[1]])
    return None if blocked[r, c] else (r, c)


def route_likelihood(grid: OccupancyGrid, arrows: Iterable[Arrow], params: RouteParams = RouteParams(),
                     searches: PathSearches | None = None, bearing_share: float = 0.0) -> np.ndarray | None:
    """The product over ``arrows`` of each one's likelihood, per cell of ``grid`` (float, max 1); None if none.
    ``searches``: path searches kept from earlier calls (the same answer, sooner). ``bearing_share``: the chance
    the arrows are fingerposts (:mod:`sim.navigation.fingerposts`), pointing at their places as the crow flies:
    each arrow's ``near`` is then that share of the same falloff of the angle between the arrow and the line from
    its reader to the cell, and the rest its route's (module docstring)."""
    searches = PathSearches() if searches is None else searches
    arrows = list(arrows)
    if not arrows:
        return None
    pool, blocked = route_cells(grid, params)
    unseen = unseen_cells(grid, pool)
    costs = route_costs(blocked, unseen, params)
    step = pool * grid.resolution
    total = np.ones(blocked.shape)
    tolerance, spread = math.radians(params.tolerance_deg), math.radians(params.spread_deg)
    for arrow in arrows:
        sign = np.asarray(arrow.sign_xy, dtype=float)
        stand = open_cell(grid, pool, blocked, sign + params.stand_m * np.array([math.cos(arrow.facing),
                                                                            math.sin(arrow.facing)]))
        if stand is None:
            continue
        if bearing_share >= 1.0:
            total *= arrow.wrong_prob + (1.0 - arrow.wrong_prob) * _bearing_near(blocked.shape, stand, arrow.direction,
                                                                                 tolerance, spread)
            continue
        lengths, pred = searches.tree("route", costs, stand)
        lead = params.lead_m / step
        leg = first_leg_points(lengths.ravel(), pred, lead)
        rows, cols = np.divmod(leg, blocked.shape[1])
        heading = np.arctan2(-(rows - stand[0]), cols - stand[1])  # rows run down the map: y is -row
        error = np.abs(np.angle(np.exp(1j * (heading - arrow.direction))))
        near = np.exp(-np.maximum(error - tolerance, 0.0) / spread).reshape(blocked.shape)
        if params.unseen_detour > 0:
            near = np.maximum(near, _unseen_way(lengths, pred, error.reshape(blocked.shape) <= tolerance, costs,
                                                unseen & (lengths <= params.unseen_reach_m / step), lead,
                                                params.unseen_detour, searches, f"leg {arrow}"))
        near[~np.isfinite(lengths)] = 1.0  # cut off from the reader: the arrow says nothing there
        near[stand] = 1.0
        if bearing_share > 0.0:
            near = bearing_share * _bearing_near(blocked.shape, stand, arrow.direction, tolerance, spread) \
                + (1.0 - bearing_share) * near
        total *= arrow.wrong_prob + (1.0 - arrow.wrong_prob) * near
    fine = unpool_cells(walls_take_front(total, blocked, params.front_m / step), pool, grid.shape)
    return fine / float(fine.max())


def _bearing_near(shape: tuple[int, int], stand: tuple[int, int], direction: float, tolerance: float,
                  spread: float) -> np.ndarray:
    """Per route cell, ``exp(-max(error - tolerance, 0) / spread)`` with ``error`` the angle (rad) between
    ``direction`` and the line from the reader's cell ``stand`` to the cell (1 at the reader)."""
    rows, cols = np.indices(shape)
    heading = np.arctan2(-(rows - stand[0]), cols - stand[1])  # rows run down the map: y is -row
    error = np.abs(np.angle(np.exp(1j * (heading - direction))))
    near = np.exp(-np.maximum(error - tolerance, 0.0) / spread)
    near[stand] = 1.0
    return near


def _unseen_way(lengths: np.ndarray, pred: np.ndarray, along: np.ndarray, costs: np.ndarray, unseen: np.ndarray,
                lead: float, share: float, searches: PathSearches, kind: str) -> np.ndarray:
    """Per route cell, how likely its true route from the reader sets off along the arrow although its shortest
    route over the robot's map does not: ``exp(-detour / (share * across))``, with ``detour`` how much longer (in
    cells, priced by ``costs``) the shortest route is that leaves the reader's circle of ``lead`` cells where the
    arrow points (``along``: each cell's first leg lies within the tolerance; the route may not come back through
    the circle) and ``across`` the cells of the shortest route that lie in ``unseen`` space (those near enough the
    reader to turn its first leg). A route over mapped space is what it is (0 where ``across`` is 0); one across
    unseen space may be longer in truth by up to ``share`` of that. Cells within the circle get 0: their first leg
    is the test."""
    flat = lengths.ravel()
    inside = flat <= lead
    rim = inside & (flat > lead - 1.5) & along.ravel()  # within one diagonal step (1.41 cells) of the circle's edge
    across = share * path_sums(pred, np.where(unseen.ravel(), 1.0, 0.0)).reshape(lengths.shape)
    if not rim.any() or not (across.ravel()[~inside] > 0).any():
        return np.zeros(lengths.shape)
    held = costs.copy().ravel()
    held[inside & ~rim] = np.inf
    starts = tuple(tuple(int(v) for v in divmod(int(i), lengths.shape[1])) for i in np.flatnonzero(rim))
    with np.errstate(invalid="ignore", divide="ignore"):
        detour = searches.lengths_from(kind, held.reshape(lengths.shape), starts) + lead - lengths
        out = np.where((across > 0) & np.isfinite(detour), np.exp(-np.maximum(detour, 0.0) / across), 0.0)
    out.ravel()[inside] = 0.0
    return out


def path_sums(pred: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Per index, the sum of ``values`` over it and its ancestors by ``pred`` (an index per index; a root points
    to itself and counts 0). By pointer jumping: each round doubles how far back a sum reaches."""
    own = np.arange(len(pred))
    acc = np.where(pred == own, 0.0, values)
    jump = pred
    for _ in range(64):
        nxt = jump[jump]
        acc = acc + acc[jump]
        if np.array_equal(nxt, jump):
            return acc
        jump = nxt
    raise ValueError("path_sums: the pointers form a cycle")


def passed_likelihood(grid: OccupancyGrid, readers: Iterable[tuple[float, float]], start_xy: np.ndarray,
                      params: RouteParams = RouteParams(), searches: PathSearches | None = None) -> np.ndarray | None:
    """Per cell of ``grid``, the likelihood that signs read at ``readers`` (where each sign's reader stands, m)
    named neither the goal nor an area holding it, given the goal there: ``1 - named_prob`` where the cell's
    shortest route from ``start_xy`` (m; over the robot's map, unseen space open at ``unseen_cost``) passes within
    ``junction_m`` of a reader and ends beyond it, 1 elsewhere (a reader that near the start says nothing); scaled
    to a peak of 1; None with no reader.

    Signs name the places whose routes pass them, so a sign that does not name the goal says the goal lies off
    the ways it stands on."""
    searches = PathSearches() if searches is None else searches
    readers = [np.asarray(r, dtype=float) for r in readers]
    if not readers:
        return None
    pool, blocked = route_cells(grid, params)
    start = open_cell(grid, pool, blocked, np.asarray(start_xy, dtype=float))
    if start is None:
        return None
    unseen = unseen_cells(grid, pool)
    lengths, pred = searches.tree("route", route_costs(blocked, unseen, params), start)
    step = pool * grid.resolution
    rows, cols = np.indices(blocked.shape)
    x0, y0 = grid.origin
    xs = x0 + (cols + 0.5) * step
    ys = y0 + (grid.shape[0] - (rows + 0.5) * pool) * grid.resolution
    total = np.ones(blocked.shape)
    for reader in readers:
        near = (np.hypot(xs - reader[0], ys - reader[1]) <= params.junction_m).ravel() & np.isfinite(lengths.ravel())
        if near[start[0] * blocked.shape[1] + start[1]]:
            continue  # every route from the start passes a sign beside it: not naming the goal says nothing
        through = near[follow_pointers(np.where(near, np.arange(near.size), pred))].reshape(blocked.shape)
        total *= np.where(through & ~near.reshape(blocked.shape), 1.0 - params.named_prob, 1.0)
    fine = unpool_cells(walls_take_front(total, blocked, params.front_m / step), pool, grid.shape)
    return fine / float(fine.max())


def walls_take_front(likelihood: np.ndarray, blocked: np.ndarray, reach_cells: float) -> np.ndarray:
    """``likelihood`` (per route cell) with each ``blocked`` cell given the most of the open cells within
    ``reach_cells`` of it. No route enters a wall, but a label on it is read from the space in front, so it is as
    likely to be the goal's as a place there; a wall with no open cell that near keeps its own."""
    reach = max(1, int(round(reach_cells)))
    front = ndimage.maximum_filter(np.where(blocked, -np.inf, likelihood), size=2 * reach + 1, mode="nearest")
    return np.where(blocked & np.isfinite(front), front, likelihood)


def first_leg_points(lengths: np.ndarray, pred: np.ndarray, lead: float) -> np.ndarray:
    """Per cell (flat), the cell where its shortest path from the search's start first leaves the ``lead``
    (cells of path) around it: the first ancestor within ``lead`` (the cell itself when within). By pointer
    jumping: each round doubles how far back a cell looks."""
    return follow_pointers(np.where(lengths <= lead, np.arange(len(lengths)), pred))  # cut off: its own


def follow_pointers(jump: np.ndarray) -> np.ndarray:
    """Per index, where following ``jump`` (an index per index) ends: at an index that points to itself. By
    pointer jumping, each round doubling how far an index looks; a ValueError when the pointers form a cycle."""
    for _ in range(64):
        nxt = jump[jump]
        if np.array_equal(nxt, jump):
            return jump
        jump = nxt
    raise ValueError("follow_pointers: the pointers form a cycle")


def door_depth_weight(grid: OccupancyGrid, start_xy: np.ndarray, params: RouteParams = RouteParams(),
                      searches: PathSearches | None = None) -> np.ndarray:
    """Per cell, ``room_weight`` to the power of the doorways crossed from ``start_xy`` (m) to the space within
    ``front_m`` of it (float, in (0, 1]; unseen space counts as open, mapped walls block).

    Searched on cells ``depth_pool`` times coarser, each as narrow as its narrowest fine cell. ``searches``:
    path searches kept from earlier calls (the same answer, sooner)."""
    searches = PathSearches() if searches is None else searches
    pool = max(1, params.depth_pool)
    res = grid.resolution * pool
    clearance = clearance_m(grid, max(params.robot_radius_m, params.door_width_m / 2))  # passable, and narrow
    coarse = pool_cells(clearance, pool, 0.0, np.min)  # off the grid counts as wall
    passable = coarse > params.robot_radius_m
    narrow = coarse < params.door_width_m / 2
    rc = np.clip(grid.world_to_cell(np.asarray(start_xy, dtype=float))[0] // pool, 0,
                 np.array(coarse.shape) - 1)
    if not passable[rc[0], rc[1]]:
        _, (ir, ic) = ndimage.distance_transform_edt(~passable, return_indices=True)
        rc = np.array([ir[rc[0], rc[1]], ic[rc[0], rc[1]]])
    seed = (int(rc[0]), int(rc[1]))
    cost = searches.lengths("doors", np.where(passable, 1.0 + params.door_penalty_m * narrow, np.inf), seed) * res
    plain = searches.lengths("plain", np.where(passable, 1.0, np.inf), seed) * res
    with np.errstate(invalid="ignore"):
        doors = np.where(np.isfinite(cost) & np.isfinite(plain), (cost - plain) / params.door_cost_m, 6.0)
    weight = params.room_weight ** np.clip(doors, 0.0, 6.0)
    reach = max(1, int(round(params.front_m / res)))
    front = ndimage.maximum_filter(weight, size=2 * reach + 1, mode="nearest")
    return unpool_cells(front, pool, grid.shape)
