"""Parameters of the abstract map, with units and the paper's values as defaults.

Sources: Section IV-A of Talbot et al. (2020) and ``shared/paper/method.md``.
Where the paper and the authors' code disagree, the field says which is used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .forces import EXPANSION_LAWS, Core

STIFFNESS: dict[str, float] = {"XL": 2.5, "L": 1.0, "M": 0.5, "S": 0.1, "XS": 0.01}
"""Named spring stiffnesses (N/m for distance springs, N/rad for angle springs)."""

LevelPair = tuple[int, int]


def _place_scales() -> dict[LevelPair, float]:
    return {(1, 1): 4.0, (1, 2): 5.0, (1, 3): 20.0, (2, 2): 15.0, (2, 3): 15.0, (3, 3): 50.0}


@dataclass(frozen=True)
class ScaleDefaults:
    """Metres per unit natural length, before any distance has been observed.

    Levels beyond a table's largest are clamped to it (a 4-level building uses
    the level-3 values for its top level until it learns its own).
    """

    place: dict[LevelPair, float] = field(default_factory=_place_scales)  # m, by (level a <= level b)
    # m, place to sign, by place level (the authors' 8 and 15; level 3 takes the label's 20)
    sign: dict[int, float] = field(default_factory=lambda: {1: 8.0, 2: 15.0, 3: 20.0})
    # m, place to its own label, by place level; never learned
    label: dict[int, float] = field(default_factory=lambda: {1: 2.0, 2: 12.5, 3: 20.0})

    def __post_init__(self) -> None:
        """Each table covers every level (pair a <= b) from 1 to its top, in metres in (0, 1e6]."""
        for table_name in ("place", "sign", "label"):
            table = getattr(self, table_name)
            if not isinstance(table, dict) or not table:
                raise ValueError(f"ScaleDefaults.{table_name} must be a non-empty table")
            for key, value in table.items():
                _positive(f"ScaleDefaults.{table_name}[{key!r}]", value)
        for table_name in ("sign", "label"):
            table = getattr(self, table_name)
            if not all(isinstance(k, int) and not isinstance(k, bool) for k in table):
                raise ValueError(f"ScaleDefaults.{table_name}: levels must be integers, got {sorted(map(str, table))}")
            top = max(table)
            if top > 100 or set(table) != set(range(1, top + 1)):
                raise ValueError(f"ScaleDefaults.{table_name}: expected levels 1 to N (N <= 100), got {sorted(table)}")
        pairs = self.place
        if not all(isinstance(k, tuple) and len(k) == 2 and all(isinstance(v, int) and not isinstance(v, bool)
                                                                for v in k) for k in pairs):
            raise ValueError(f"ScaleDefaults.place: keys must be level pairs (a, b), got {list(pairs)[:5]}")
        top = max(max(k) for k in pairs)
        expected = {(a, b) for a in range(1, top + 1) for b in range(a, top + 1)}
        if top > 100 or set(pairs) != expected:
            raise ValueError(f"ScaleDefaults.place: expected every level pair a <= b from 1 to N (N <= 100), "
                             f"got {sorted(pairs)[:10]}")


@dataclass(frozen=True)
class DynamicsParams:
    """Spring-mass integration and settling (Algorithm 1)."""

    mass: float = 1.0  # kg, every point mass
    friction: float = 0.1  # N s/m, viscous friction coefficient
    expansion: float = 0.01  # N (constant law) or N/m (proportional law)
    expansion_law: str = "constant"  # "constant" (authors' code) or "proportional" (paper's text)
    expansion_on: str = "leaves"  # "leaves" (authors' code) or "all" free masses
    min_separation: float = 0.2  # m between free masses (they bounce)
    # m, the angle springs' energy fades as (r / floor)^2 within floor = max(angle_core, angle_core_share * l) of
    # their pivot, where the direction is ill-defined (the authors' code faded the force to zero inside the same
    # 0.5 m); the force stays the energy's gradient (forces.py), so nothing can circle a pivot for ever
    angle_core: float = 0.5
    # of an angle spring's l: the floor is at least this share of l, so no angle spring pushes tangentially harder
    # than 1 / share times the paper's K * error: a place that passes close to a pivot is not flung round it
    angle_core_share: float = 0.25
    # w dt (rad) the steepest part of a core may reach: within the floor a spring's pull toward its pivot stiffens
    # to K l error^2 / floor^2 (<= pi^2 K l / floor^2), so the floor is at least pi dt sqrt(K l / mass) / this.
    # pymunk's semi-implicit Euler is stable below 2; 1 leaves room for springs that share a pivot (their
    # stiffnesses add). Without it a place on its context's pivot (two "past" springs, development office seed 16)
    # shook there at 0.13 m/s and its settle never ended
    angle_core_wdt: float = 1.0
    # m, l of an angle spring with no distance spring between its places: its force K * error * l / r is the
    # paper's K * error at r = l (forces.py)
    angle_length: float = 1.0
    # Chipmunk's solver iterations per step. Only collisions between masses need more than one (a spring with
    # no damping acts in one impulse); 3 keeps colliding masses apart at half the step cost of pymunk's 10
    solver_iterations: int = 3
    # m/s^2, a mass held still joins a settle when the net force on it would accelerate it at this or more.
    # Above 0.02 (the expansion force, 0.01 N a leaf, turned right round by a move of the explored centre) so
    # the robot's moving alone wakes nothing; well below L_a (0.1), as a weakly held place (a hierarchy spring
    # is 0.01 N/m) would otherwise be left metres from where a full settle puts it. On the Lion replay a full
    # settle (0 here) and this one differ by 3.6 m at the 90th percentile of places (median 0.05 m), 0.1 by 5.2 m
    wake_acceleration: float = 0.025
    # s, integration step (the paper: Runge-Kutta at 0.1; here pymunk's semi-implicit Euler). A settle lasts as
    # long in model time whatever the step (friction takes e-fold 2 m / c = 20 s off an oscillation), so the
    # step sets how many steps it costs. Semi-implicit Euler is stable while w dt < 2; the stiffest spring the
    # model makes is an angle spring at its core, held to w dt <= angle_core_wdt (1) by the core's floor whatever
    # the step (a label's floor is then 0.99 m at 0.2 s, 0.5 m at 0.1 s; the floor grows with the step, so a
    # longer step blurs angles near their pivots instead of shaking). On generated campuses (500 places, development
    # seeds 0 and 1, 360 cues) positions after every settle agree with 0.1 s to a median of 0.0 m and a 90th
    # percentile of 0.6-0.8 m, within Algorithm 1's own tolerance (a place held at 0.01 N/m may stop 10 m from
    # its rest), as many settles converge, and a settle takes half the steps
    dt: float = 0.2
    settle_acceleration: float = 0.1  # m/s^2, L_a
    settle_velocity: float = 0.1  # m/s, L_v
    # steps before settle() gives up and reports "not settled": a guard, not part of the method (Algorithm 1
    # steps until settled). A building sign on a generated campus of 5,000 places (development seed 0, cue
    # 817) wakes the campus through its hierarchy and is at rest after 20,107 steps; 50,000 is 2.5 times that
    # (at 5,000 it stopped 12 of 2,352 settles still moving). A caller that cannot wait caps a call by time
    # (``settle(max_s=...)``)
    max_iterations: int = 50_000

    @property
    def core(self) -> Core:
        """Where the angle springs' energy fades round their pivots (forces.py)."""
        steep = math.pi * self.dt / (self.angle_core_wdt * math.sqrt(self.mass))  # m per sqrt(N m/rad)
        return Core(self.angle_core, self.angle_core_share, steep)

    def __post_init__(self) -> None:
        _choice("DynamicsParams.expansion_law", self.expansion_law, tuple(EXPANSION_LAWS))
        _choice("DynamicsParams.expansion_on", self.expansion_on, ("leaves", "all"))
        for name in ("mass", "settle_acceleration", "settle_velocity", "angle_length", "wake_acceleration",
                     "angle_core", "angle_core_wdt"):
            _positive(f"DynamicsParams.{name}", getattr(self, name))
        _positive("DynamicsParams.dt", self.dt, high=10.0)
        if isinstance(self.max_iterations, bool) or not isinstance(self.max_iterations, int):
            raise ValueError(f"DynamicsParams.max_iterations must be an integer, got {self.max_iterations!r}")
        _positive("DynamicsParams.max_iterations", self.max_iterations, high=1e6)
        if isinstance(self.solver_iterations, bool) or not isinstance(self.solver_iterations, int) \
                or not 1 <= self.solver_iterations <= 100:
            raise ValueError(f"DynamicsParams.solver_iterations must be an integer in [1, 100], "
                             f"got {self.solver_iterations!r}")
        _positive("DynamicsParams.angle_core_share", self.angle_core_share, allow_zero=True, high=1.0)
        for name in ("friction", "expansion", "min_separation"):
            _positive(f"DynamicsParams.{name}", getattr(self, name), allow_zero=True)


@dataclass(frozen=True)
class ExplorationParams:
    """Exploration factor E applied to imagined distance springs."""

    step: float = 0.25  # 25 % per bump
    law: str = "multiplicative"  # "multiplicative" (paper: E *= 1 + step) or "additive" (authors: E += step)
    # E stops growing here (1.25**20 ~ 87): imagined distances 100 times the building's scale are past any
    # building, and an unbounded E would overflow to inf after ~3,000 bumps
    max_factor: float = 100.0

    def __post_init__(self) -> None:
        _choice("ExplorationParams.law", self.law, ("multiplicative", "additive"))
        _positive("ExplorationParams.step", self.step, high=10.0)
        _positive("ExplorationParams.max_factor", self.max_factor, high=1e4)
        if self.max_factor < 1.0:
            raise ValueError(f"ExplorationParams.max_factor must be >= 1, got {self.max_factor!r}")


@dataclass(frozen=True)
class AbstractMapParams:
    """Everything that tunes an abstract map."""

    scales: ScaleDefaults = field(default_factory=ScaleDefaults)
    dynamics: DynamicsParams = field(default_factory=DynamicsParams)
    exploration: ExplorationParams = field(default_factory=ExplorationParams)
    start_stiffness: str = "S"  # the start pose's pull on the hierarchy root(s), a STIFFNESS name
    between_angle: bool = True  # add the relative angle of pi at the figure between two referents
    # The start's pull (a STIFFNESS name, N/m and N/rad) on the first place of each group of places that no
    # chain of springs ties to a fixed point (e.g. an untagged "X is near Y" about two unknown places), as
    # on a hierarchy root. Without it the expansion force (0.01 N against 0.1 N s/m of friction) drives such
    # a group at 0.1 m/s for as long as a settle runs: ~50 m per settle, without limit. With it the group's
    # drift is bounded: it rests one label scale (2 m for a leaf) ahead of the start until a cue ties it in.
    loose_stiffness: str = "S"

    def __post_init__(self) -> None:
        _choice("AbstractMapParams.start_stiffness", self.start_stiffness, tuple(STIFFNESS))
        _choice("AbstractMapParams.loose_stiffness", self.loose_stiffness, tuple(STIFFNESS))
        if not isinstance(self.between_angle, bool):
            raise ValueError(f"AbstractMapParams.between_angle must be true or false, got {self.between_angle!r}")


def _choice(name: str, value: str, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise ValueError(f"{name} is {value!r}; expected one of {list(allowed)}")


def _positive(name: str, value: float, *, allow_zero: bool = False, high: float = 1e6) -> None:
    """A real number (not a bool) in (0, high], or [0, high] with ``allow_zero``."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    try:
        ok = ok and math.isfinite(value) and (value >= 0 if allow_zero else value > 0) and value <= high
    except OverflowError:
        ok = False
    if not ok:
        raise ValueError(f"{name} must be a finite number {'>= 0' if allow_zero else '> 0'} and <= {high:g}, "
                         f"got {value!r}"[:300])
