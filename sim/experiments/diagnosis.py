"""Why a trial did not find its goal: one explanation per failure, from its path and the world's truth.

The reason a trial ended (the time cap, say) says when it stopped, not why
the goal's label went unread. The explanation asks the perception's own
reading rules (range and reading cone, :func:`sim.world.visibility.readable`)
of every place the camera looked from, and what the robot knew. The first
kind of :data:`KINDS` that holds is the explanation:

- the label was readable from the path, yet not read (camera detections can
  miss; geometric perception reads every label its rules allow);
- walls hid it whenever the path was in its range and cone;
- the path came within range only beside or behind the label, outside its
  reading cone (a label beside a door, passed edge-on or turned away from);
- the path never came within range, and then by what the robot knew: the
  abstract map imagined the goal more than a reading range from its label,
  or near it (the robot did not get there), or no sign it read named the goal
  (or the navigator reads no signs).

Frames: world, metres, radians counter-clockwise from +x.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from abstract_map.clauses import clause_names
from abstract_map.errors import CueError
from abstract_map.grammar import Anchor, parse_cue
from sim.world.visibility import off_normal, readable

KINDS = {  # kind -> what it means, in the order they are tried
    "readable, not read": "the label was in range, inside its reading cone and in sight, yet not read",
    "hidden by walls": "in range and inside the label's cone only where walls hid it",
    "passed edge-on": "within range of the label only beside or behind it, outside its reading cone",
    "imagined elsewhere": "never within range; the abstract map imagined the goal beyond reading range of its label",
    "not reached": "never within range; the abstract map imagined the goal within reading range of its label",
    "never named": "never within range; no sign the robot read named the goal",
    "reads no signs": "never within range; the navigator reads no signs",
}

Sight = Callable[[np.ndarray, int], np.ndarray]
"""``sight(points, label)``: whether walls leave label number ``label`` in sight from each camera position of
``points`` ((N, 2), m): a bool array (N,)."""


@dataclass(frozen=True)
class Explanation:
    """Why a goal's label went unread: a kind of :data:`KINDS` and one line of particulars."""

    kind: str
    detail: str

    def __str__(self) -> str:
        return f"{self.kind}: {self.detail}"


@dataclass(frozen=True)
class ReadingRules:
    """The perception's reading rules (as :class:`sim.perception.geometric.GeometricParams` states them)."""

    max_range_m: float = 4.0  # m, floor-plane distance camera -> label
    cone_half_angle_deg: float = 45.0  # deg, half-angle of the reading cone about the label's normal


def explain(times: np.ndarray, cameras: np.ndarray, labels: Sequence[tuple[float, float, float]], *,
            rules: ReadingRules, sight: Sight | None = None, named: bool | None,
            imagined: tuple[float, float] | None) -> Explanation:
    """Why none of the goal's ``labels`` (x m, y m, facing rad) was read from camera positions ``cameras``
    ((N, 2), m) at ``times`` ((N,), s of simulated time).

    ``sight`` tests walls (None: nothing is hidden); ``named``: whether a sign the robot read named the goal
    (None: the navigator reads no signs); ``imagined``: the abstract map's last imagined goal (m), if any."""
    if not labels:
        raise ValueError("explain: the goal has no label")
    cameras = np.asarray(cameras, dtype=float).reshape(-1, 2)
    times = np.asarray(times, dtype=float).reshape(-1)
    best: tuple[int, str] | None = None  # (kind's rank, particulars), the lowest rank over the labels
    nearest = math.inf
    for number, (x, y, facing) in enumerate(labels):
        dx, dy = cameras[:, 0] - x, cameras[:, 1] - y
        distance = np.hypot(dx, dy)
        if len(distance):
            nearest = min(nearest, float(distance.min()))
        in_range = (distance <= rules.max_range_m) & (distance > 0.0)
        if not in_range.any():
            continue
        in_cone = readable(cameras[:, 0], cameras[:, 1], x, y, facing, max_range_m=rules.max_range_m,
                           cone_half_angle_deg=rules.cone_half_angle_deg)
        off = np.degrees(off_normal(cameras[:, 0], cameras[:, 1], x, y, facing))
        if in_cone.any():
            chosen = np.flatnonzero(in_cone)
            clear = np.ones(len(chosen), dtype=bool) if sight is None else np.asarray(sight(cameras[chosen], number))
            if clear.any():
                i = int(chosen[np.flatnonzero(clear)[0]])
                found = (0, f"first at {times[i]:.0f} s, {distance[i]:.1f} m away, {off[i]:.0f} deg off its facing")
            else:
                i = int(chosen[np.argmin(distance[chosen])])
                found = (1, f"nearest in its cone {distance[i]:.1f} m, at {times[i]:.0f} s")
        else:
            within = np.flatnonzero(in_range)
            i = int(within[np.argmin(distance[within])])
            found = (2, f"nearest {distance[i]:.1f} m at {times[i]:.0f} s, {off[i]:.0f} deg off its facing "
                        f"(the cone is {rules.cone_half_angle_deg:.0f})")
        if best is None or found[0] < best[0]:
            best = found
    kinds = list(KINDS)
    if best is not None:
        return Explanation(kinds[best[0]], best[1])
    near = f"nearest {nearest:.1f} m"
    if named is None:
        return Explanation("reads no signs", near)
    if not named:
        return Explanation("never named", near)
    if imagined is None:
        return Explanation("imagined elsewhere", f"{near}; no imagined position")
    miss = min(math.hypot(imagined[0] - x, imagined[1] - y) for x, y, _ in labels)
    kind = "imagined elsewhere" if miss > rules.max_range_m else "not reached"
    return Explanation(kind, f"{near}; imagined {miss:.1f} m from its label")


def names_place(text: str, anchor: Anchor, place: str) -> bool:
    """Whether the sign ``text`` hung at ``anchor`` names ``place`` (case aside) in any of its clauses. A sign the
    grammar cannot read names nothing (the abstract map refuses it too)."""
    try:
        clauses = parse_cue(text, anchor, kind="sign")
    except CueError:
        return False
    wanted = place.casefold()
    return any(name.casefold() == wanted for clause in clauses for name in clause_names(clause))
