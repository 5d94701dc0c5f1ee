"""Spotting: tags seen to be there (8 m, 75 degrees) though too far or too oblique to read."""

from __future__ import annotations

import dataclasses
import math

import pytest

pytest.importorskip("pybullet")

from sim.perception import GeometricPerception  # noqa: E402
from sim.perception.spotting import Spot, Spotter  # noqa: E402
from sim.world.robot import Robot  # noqa: E402
from tests.sim.perception.test_perception import CASES  # noqa: E402

POSES = {name: pose for name, pose, _, _ in CASES}


@pytest.fixture(scope="module")
def robot(tiny_scene):
    return Robot(tiny_scene)


def _near(spots, tag):
    return any(math.hypot(s.x - tag.x, s.y - tag.y) < 0.1 for s in spots)


@pytest.mark.parametrize("name, tag_id, spotted", [
    ("oblique 70 deg at 2 m", 0, True),  # too oblique to read, not to see
    ("past 4 m", 0, True),  # too far to read, not to see
    ("through a wall", 2, False),
    ("wall tag from the wrong side", 3, False),
    ("behind a free-standing tag", 1, False),
])
def test_tags_are_spotted_where_they_cannot_be_read(tiny_world, tiny_scene, robot, name, tag_id, spotted):
    robot.reset(*POSES[name])
    tiny_scene.step(5)
    spots = Spotter(tiny_scene).spot(robot)
    assert _near(spots, tiny_world.tags[tag_id]) == spotted, name
    if spotted:
        read = GeometricPerception(tiny_scene).observe(robot)
        assert tag_id not in {s.tag_id for s in read}


def test_a_spot_says_where_a_tag_hangs_not_what_it_says():
    assert {f.name for f in dataclasses.fields(Spot)} == {"x", "y", "theta", "range_m"}
