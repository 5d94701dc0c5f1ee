"""A failed trial's explanation: the first kind whose rule holds along the path."""

from __future__ import annotations

import math

import numpy as np
import pytest

from abstract_map.grammar import Anchor
from sim.experiments.diagnosis import KINDS, ReadingRules, explain, names_place

RULES = ReadingRules(max_range_m=4.0, cone_half_angle_deg=45.0)
LABEL = (0.0, 0.0, math.pi / 2)  # at the origin, facing +y: readable from above it


def path(*points: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Camera positions, one a second."""
    return np.arange(len(points), dtype=float), np.array(points, dtype=float)


def test_a_label_readable_from_the_path_is_readable_not_read():
    times, cameras = path((10.0, 3.0), (1.0, 3.0), (-10.0, 3.0))
    got = explain(times, cameras, [LABEL], rules=RULES, named=True, imagined=(0.0, 0.0))
    assert got.kind == "readable, not read"
    assert got.detail.startswith("first at 1 s, 3.2 m away, 18 deg off its facing")


def test_walls_that_hide_every_readable_pose_are_the_explanation():
    times, cameras = path((10.0, 3.0), (1.0, 3.0), (-10.0, 3.0))
    got = explain(times, cameras, [LABEL], rules=RULES, sight=lambda points, label: np.zeros(len(points), bool),
                  named=True, imagined=None)
    assert got.kind == "hidden by walls"


def test_passing_beside_or_behind_the_label_is_passing_it_edge_on():
    times, cameras = path((10.0, 0.5), (1.0, 0.5), (0.0, -1.0), (-10.0, 0.5))  # along its wall, then behind it
    got = explain(times, cameras, [LABEL], rules=RULES, named=True, imagined=(0.0, 0.0))
    assert got.kind == "passed edge-on"
    assert got.detail.startswith("nearest 1.0 m at 2 s, 180 deg off its facing")


@pytest.mark.parametrize(("named", "imagined", "kind", "detail"), [
    (True, (30.0, 0.0), "imagined elsewhere", "nearest 20.0 m; imagined 30.0 m from its label"),
    (True, (3.0, 0.0), "not reached", "nearest 20.0 m; imagined 3.0 m from its label"),
    (False, (3.0, 0.0), "never named", "nearest 20.0 m"),
    (None, None, "reads no signs", "nearest 20.0 m"),
])
def test_a_path_that_never_came_within_range_is_explained_by_what_the_robot_knew(named, imagined, kind, detail):
    times, cameras = path((20.0, 0.0), (20.0, 10.0))
    got = explain(times, cameras, [LABEL], rules=RULES, named=named, imagined=imagined)
    assert (got.kind, got.detail) == (kind, detail)
    assert str(got) == f"{kind}: {detail}"


def test_of_several_labels_the_nearest_to_being_read_explains():
    times, cameras = path((10.0, 0.5), (1.0, 0.5), (30.0, 3.0))
    got = explain(times, cameras, [(30.0, 0.0, math.pi / 2), LABEL], rules=RULES, named=True, imagined=None)
    assert got.kind == "readable, not read"  # the first label; the second was passed edge-on


def test_every_kind_is_described_and_a_goal_without_a_label_is_refused():
    assert all(KINDS.values())
    with pytest.raises(ValueError, match="no label"):
        explain(np.zeros(1), np.zeros((1, 2)), [], rules=RULES, named=True, imagined=None)


def test_a_sign_names_the_places_its_arrows_and_phrases_mention():
    here = Anchor("#7", 1.0, 2.0, math.pi)
    sign = "$LEFT$ Training Studio, Marketing Print Room\n$UP$ Lobby\nSales Lab is past Lobby"
    assert names_place(sign, here, "marketing print room")
    assert names_place(sign, here, "Sales Lab") and names_place(sign, here, "Lobby")
    assert not names_place(sign, here, "Marketing Print Room 2")  # a name it only begins
    assert not names_place("$SIDEWAYS$ Lobby", here, "Lobby")  # unreadable: names nothing
