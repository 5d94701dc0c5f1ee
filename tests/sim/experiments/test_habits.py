"""How a walk moved (sim.experiments.habits): turnarounds, ground walked again, weave and doorways.

The plan here: a 10 x 6 m box (0.05 m pixels, origin at 0, 0), a wall along y = 3.0-3.2 m splitting it into
a corridor (south) and a room (north), with a 1 m door at x = 4.5-5.5 m and a 2 m opening (a hall exit, no
door) at x = 7.5-9.5 m.
"""

from __future__ import annotations

import numpy as np
import pytest

from sim.experiments.habits import (
    HabitParams,
    Habits,
    doorway_cells,
    doorway_entries,
    doorway_plates,
    habits,
    habits_table,
    resample,
    revisited_m,
    study_habits,
    totals,
    turnarounds,
    weave,
)
from sim.world.data import Floorplan, Tag

RES = 0.05


def plan() -> Floorplan:
    rows, cols = int(6 / RES), int(10 / RES)
    occupied = np.zeros((rows, cols), dtype=bool)
    occupied[:4, :] = occupied[-4:, :] = True  # outer walls, 0.2 m
    occupied[:, :4] = occupied[:, -4:] = True
    wall = slice(rows - int(3.2 / RES), rows - int(3.0 / RES))  # y = 3.0-3.2 m (row 0 is the top)
    occupied[wall, :] = True
    occupied[wall, int(4.5 / RES):int(5.5 / RES)] = False  # the door
    occupied[wall, int(7.5 / RES):int(9.5 / RES)] = False  # the wide opening
    return Floorplan(occupied, RES, (0.0, 0.0))


def legs(*corners: tuple[float, float], step_m: float = 0.05) -> np.ndarray:
    """(N, 2) m points along straight legs through ``corners``."""
    points = [np.asarray(corners[0], dtype=float)]
    for a, b in zip(corners, corners[1:]):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / step_m)))
        points += [a + (b - a) * k / n for k in range(1, n + 1)]
    return np.array(points)


def test_resampling_keeps_the_length_and_the_ends():
    points = resample(legs((0.0, 0.0), (3.0, 0.0), (3.0, 2.0)), 0.25)
    assert len(points) == 21 and np.allclose(points[0], (0.0, 0.0)) and np.allclose(points[-1], (3.0, 2.0))
    assert resample(np.zeros((0, 2)), 0.25).shape == (0, 2)


def test_the_one_metre_door_is_a_doorway_and_the_two_metre_opening_is_not():
    pooled, doorways = doorway_cells(plan())
    assert doorways.max() == 1  # one doorway
    cells = np.argwhere(doorways == 1)
    xs = pooled.origin[0] + (cells[:, 1] + 0.5) * pooled.resolution
    ys = pooled.origin[1] + (pooled.shape[0] - cells[:, 0] - 0.5) * pooled.resolution
    assert 4.5 < xs.min() and xs.max() < 5.5 and 2.8 < ys.min() and ys.max() < 3.4


def test_a_walk_into_the_room_and_out_passes_the_door_twice_and_turns_round_once():
    pooled, doorways = doorway_cells(plan())
    walk = legs((1.0, 1.5), (5.0, 1.5), (5.0, 5.0), (5.0, 1.5), (9.0, 1.5))
    h = habits(walk, pooled, doorways)
    assert h.doorways == 2 and h.doorways_again == 0
    assert h.turnarounds == 1  # back out of the room, not the two corners
    assert h.revisited_m == 0.0  # a spur shorter than half revisit_gap_m is a turnaround, not a place returned to
    in_again = legs((1.0, 1.5), (5.0, 1.5), (5.0, 5.0), (5.0, 1.5), (7.0, 1.5), (5.0, 1.5), (5.0, 5.0))
    again = habits(in_again, pooled, doorways)
    assert again.doorways == 3 and again.doorways_again == 1  # the room entered a second time


def test_the_wide_opening_and_swaying_on_the_threshold_are_no_new_doorways():
    pooled, doorways = doorway_cells(plan())
    through_opening = legs((1.0, 1.5), (8.5, 1.5), (8.5, 5.0))
    assert habits(through_opening, pooled, doorways).doorways == 0
    sway = legs((5.0, 1.5), (5.0, 3.1), (5.0, 2.6), (5.0, 3.1), (5.0, 4.5))
    assert [door for _, door in doorway_entries(resample(sway, HabitParams().step_m), pooled, doorways)] == [1]


def test_turning_in_before_reading_the_doors_plate_is_counted_from_the_plates_side_only():
    """The door's plate hangs on the corridor side 0.85 m east of the door, facing the corridor (-y); a sign
    and a label far from any door are no plates."""
    pooled, doorways = doorway_cells(plan())
    plate = Tag(7, 5.85, 3.0, -np.pi / 2, "label", "Room")
    plates = doorway_plates(pooled, doorways, [plate, Tag(8, 5.85, 3.0, -np.pi / 2, "sign", "$UP$ Room"),
                                               Tag(9, 2.0, 0.2, np.pi / 2, "label", "Far")])
    assert plates == {1: [plate]}
    walk = legs((1.0, 1.5), (5.0, 1.5), (5.0, 5.0), (5.0, 1.5))  # in, and back out
    times = np.linspace(0.0, 20.0, len(walk))  # the door is first entered about 9 s in
    enter = habits(walk, pooled, doorways, times=times, plates=plates, read_s={})
    assert enter.doorways == 2 and enter.entered_unread == 1  # in unread; coming out is from the room's side
    assert habits(walk, pooled, doorways, times=times, plates=plates, read_s={7: 5.0}).entered_unread == 0
    assert habits(walk, pooled, doorways, times=times, plates=plates, read_s={7: 15.0}).entered_unread == 1
    assert habits(walk, pooled, doorways).entered_unread is None  # reads unknown


def test_a_straight_walk_neither_turns_nor_revisits_nor_weaves():
    straight = resample(legs((0.0, 0.0), (20.0, 0.0)), HabitParams().step_m)
    assert turnarounds(straight) == 0 and revisited_m(straight) == 0.0
    beyond, walked = weave(straight)
    assert beyond == pytest.approx(0.0, abs=1e-9) and walked == pytest.approx(20.0)


def test_a_zig_zag_weaves_and_a_shuttle_turns_round_each_time():
    zig = resample(legs(*[(x, 0.4 * (x % 2)) for x in range(21)]), HabitParams().step_m)
    beyond, walked = weave(zig)
    assert walked > 0 and beyond / walked == pytest.approx(np.hypot(1, 0.4) - 1, rel=0.25)
    shuttle = resample(legs((0.0, 0.0), (10.0, 0.0), (0.0, 0.0), (10.0, 0.0)), HabitParams().step_m)
    assert turnarounds(shuttle) == 2
    # back: the half walked 10 m or more after its first pass (5 m); out again: all of it (10 m)
    assert revisited_m(shuttle) == pytest.approx(15.0, abs=0.6)


def test_totals_are_per_100_m_per_walk_and_shares():
    walks = [Habits(100.0, 2, 10.0, 1.0, 50.0, 4, 1, 2), Habits(100.0, 0, 0.0, 0.0, 50.0, 0, 0)]
    t = totals(walks)
    assert t["turnarounds per 100 m"] == 1.0 and t["revisited %"] == 5.0 and t["weave %"] == 1.0
    assert t["doorways per walk"] == 2.0 and t["doorways again per walk"] == 0.5
    assert t["entered unread per walk"] == 2.0  # over the one walk whose reads are known
    assert np.isnan(totals([])["doorways per walk"])


def test_a_studys_habits_come_per_navigator_and_group_with_the_oracles_once_per_goal(tiny_world):
    """Two navigators walk the tiny world's goal in two groups; a record without a walk and one of a world not
    loaded are counted, not measured."""
    walk = [[0.4 * i, 1.0 + 0.1 * i, 1.0, 0.0] for i in range(40)]
    cue = [{"tag_id": 0, "t_s": 10.0}]
    records = [{"world": "tiny", "goal": "A", "navigator": n, "signage": g, "trajectory": walk, "cues": cue}
               for n in ("guided", "paper") for g in ("complete", "sparse")]
    records += [{"world": "tiny", "goal": "A", "navigator": "paper", "signage": "sparse", "trajectory": []},
                {"world": "elsewhere", "goal": "A", "navigator": "paper", "signage": "sparse", "trajectory": walk}]
    rows, unmeasured = study_habits(records, {"tiny": tiny_world}, lambda r: r["signage"])
    assert unmeasured == 2
    assert sorted(rows) == [(n, g) for n in ("guided", "oracle", "paper") for g in ("complete", "sparse")]
    assert all(len(walks) == 1 for walks in rows.values())
    assert rows["guided", "sparse"][0].walked_m == pytest.approx(3.9)
    assert rows["guided", "sparse"][0].entered_unread == 0 and rows["oracle", "sparse"][0].entered_unread is None
    table = habits_table(rows, "signage")
    assert table[0].startswith("| navigator | signage | walks | walked (m) | turnarounds per 100 m")
    assert len(table) == 2 + 6 and "| oracle | complete | 1 |" in table[4]
