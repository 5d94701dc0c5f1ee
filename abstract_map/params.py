"""Parameters of the abstract map, with units and the paper's values as defaults.

Sources: Section IV-A of Talbot et al. (2020) and ``shared/paper/method.md``.
Where the paper and the authors' code disagree, the field says which is used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

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


@dataclass(frozen=True)
class DynamicsParams:
    """Spring-mass integration and settling (Algorithm 1)."""

    mass: float = 1.0  # kg, every point mass
    friction: float = 0.1  # N s/m, viscous friction coefficient
    expansion: float = 0.01  # N (constant law) or N/m (proportional law)
    expansion_law: str = "constant"  # "constant" (authors' code) or "proportional" (paper's text)
    expansion_on: str = "leaves"  # "leaves" (authors' code) or "all" free masses
    min_separation: float = 0.2  # m between free masses (they bounce)
    angle_core: float = 0.5  # m, angle spring forces fade to zero inside this distance of their pivot
    dt: float = 0.1  # s, integration step (paper: Runge-Kutta with dt 0.1; here pymunk's integrator)
    settle_acceleration: float = 0.1  # m/s^2, L_a
    settle_velocity: float = 0.1  # m/s, L_v
    max_iterations: int = 5000  # steps before settle() gives up and reports "not settled"

    def __post_init__(self) -> None:
        _choice("DynamicsParams.expansion_law", self.expansion_law, ("constant", "proportional"))
        _choice("DynamicsParams.expansion_on", self.expansion_on, ("leaves", "all"))
        for name in ("mass", "dt", "settle_acceleration", "settle_velocity", "max_iterations"):
            _positive(f"DynamicsParams.{name}", getattr(self, name))
        for name in ("friction", "expansion", "min_separation", "angle_core"):
            _positive(f"DynamicsParams.{name}", getattr(self, name), allow_zero=True)


@dataclass(frozen=True)
class ExplorationParams:
    """Exploration factor E applied to imagined distance springs."""

    step: float = 0.25  # 25 % per bump
    law: str = "multiplicative"  # "multiplicative" (paper: E *= 1 + step) or "additive" (authors: E += step)

    def __post_init__(self) -> None:
        _choice("ExplorationParams.law", self.law, ("multiplicative", "additive"))
        _positive("ExplorationParams.step", self.step)


@dataclass(frozen=True)
class AbstractMapParams:
    """Everything that tunes an abstract map."""

    scales: ScaleDefaults = field(default_factory=ScaleDefaults)
    dynamics: DynamicsParams = field(default_factory=DynamicsParams)
    exploration: ExplorationParams = field(default_factory=ExplorationParams)
    start_stiffness: str = "S"  # the start pose's pull on the hierarchy root(s), a STIFFNESS name
    between_angle: bool = True  # add the relative angle of pi at the figure between two referents

    def __post_init__(self) -> None:
        _choice("AbstractMapParams.start_stiffness", self.start_stiffness, tuple(STIFFNESS))


def _choice(name: str, value: str, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise ValueError(f"{name} is {value!r}; expected one of {list(allowed)}")


def _positive(name: str, value: float, *, allow_zero: bool = False) -> None:
    if not (math.isfinite(value) and (value >= 0 if allow_zero else value > 0)):
        raise ValueError(f"{name} must be finite and {'>= 0' if allow_zero else '> 0'}, got {value!r}")
