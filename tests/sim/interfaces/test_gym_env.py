"""The Gymnasium environment: the API checker, seeding, the episode's end, our navigator through it."""

from __future__ import annotations

import math

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

from sim.experiments.trial import TrialParams, run_trial  # noqa: E402
from sim.interfaces import ENV_ID  # noqa: E402
from sim.interfaces.gym_env import FindPlaceEnv, _wheels  # noqa: E402
from sim.interfaces.observation import from_frame, to_frame  # noqa: E402
from sim.world.robot import RobotParams  # noqa: E402

MAKE_ID = f"sim.interfaces:{ENV_ID}"


def make(world, **kwargs):
    return gymnasium.make(MAKE_ID, world=str(world.root), **kwargs)


def test_the_env_passes_gymnasiums_checker(tiny_world):
    from gymnasium.utils.env_checker import check_env

    env = make(tiny_world, perception="geometric", render_mode="rgb_array")
    try:
        check_env(env.unwrapped)
        env.reset(seed=0)
        image = env.render()
        assert image.ndim == 3 and image.shape[2] == 3 and image.dtype == np.uint8
    finally:
        env.close()


def test_same_seed_same_episode(tiny_world):
    env = make(tiny_world, perception="geometric")
    runs = []
    for _ in range(2):
        obs, _ = env.reset(seed=7)
        env.action_space.seed(7)
        trace = [obs["odometry"].copy()]
        for _ in range(15):
            obs, *_ = env.step(env.action_space.sample())
            trace.append(obs["odometry"].copy())
        runs.append(np.array(trace))
    env.close()
    assert np.array_equal(runs[0], runs[1])
    assert np.ptp(runs[0][:, :2], axis=0).max() > 0.01  # the random actions moved the robot


def test_our_navigator_finds_the_goal_through_the_env_as_in_a_trial(tiny_world):
    # The tiny world's goal label is out of reading range at the start; a short drive reads it.
    env = make(tiny_world, goal="A", perception="geometric")
    obs, info = env.reset(seed=3)
    assert info["goal"] == "A"
    policy = env.unwrapped.navigator_policy()
    total, steps = 0.0, 0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += reward
        steps += 1
        if terminated or truncated:
            break
    env.close()
    assert terminated and not truncated and info["reason"] == "goal label read"
    assert 0 in info["cues"] and info["cues"][0] == "A"
    assert total == pytest.approx(10.0 - info["distance_m"])
    trial = run_trial(tiny_world, "A", seed=3, perception="geometric", navigator=env.unwrapped.navigator)
    assert info["distance_m"] == pytest.approx(trial.distance_m, rel=0.05, abs=0.05)


def test_the_time_cap_truncates(tiny_world):
    env = make(tiny_world, goal="A", perception="geometric", params=TrialParams(max_sim_s=0.3))
    env.reset(seed=0)
    for _ in range(10):
        _, reward, terminated, truncated, info = env.step(np.zeros(2))
        if terminated or truncated:
            break
    env.close()
    assert truncated and not terminated and "time cap" in info["reason"]
    assert reward == pytest.approx(0.0, abs=1e-3)


def test_tags_are_reported_in_the_robot_frame(tiny_world):
    env = make(tiny_world, goal="A", perception="geometric")
    env.reset(seed=0)
    trial = env.unwrapped.trial
    seen = None
    for _ in range(40):
        obs, *_ = env.step(np.array([0.3, 0.0]))
        if obs["tags"]["valid"].any():
            seen = obs
            break
    env.close()
    assert seen is not None, "driving towards the label reads it"
    slot = int(np.argmax(seen["tags"]["valid"]))
    tag = tiny_world.tags[int(seen["tags"]["id"][slot])]
    x, y, theta = from_frame(tuple(seen["odometry"]), *seen["tags"]["pose"][slot])
    assert (x, y) == pytest.approx((tag.x, tag.y), abs=1e-6)
    assert math.remainder(theta - tag.theta, math.tau) == pytest.approx(0.0, abs=1e-6)
    assert trial.success or trial.sightings


def test_frames_round_trip():
    pose = (1.0, -2.0, 2.5)
    rel = to_frame(pose, 4.0, 3.0, -1.0)
    assert from_frame(pose, *rel) == pytest.approx((4.0, 3.0, -1.0))
    assert to_frame((0.0, 0.0, math.pi / 2), 0.0, 1.0, math.pi / 2) == pytest.approx((1.0, 0.0, 0.0))


def test_wheel_speeds_are_a_twist():
    robot = RobotParams()
    v, w = _wheels(np.array([0.2, 0.3]), robot)
    assert v == pytest.approx(0.25) and w == pytest.approx(0.1 / robot.wheel_separation)


def test_bad_arguments_are_errors(tiny_world):
    with pytest.raises(ValueError, match="action"):
        FindPlaceEnv(str(tiny_world.root), action="jump")
    with pytest.raises(ValueError, match="Narnia"):
        FindPlaceEnv(str(tiny_world.root), goal="Narnia")
    env = FindPlaceEnv(str(tiny_world.root))
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(np.zeros(2))


def has_generator() -> bool:
    try:
        import sim.world.generator  # noqa: F401
    except ModuleNotFoundError as exc:
        if exc.name != "sim.world.generator":
            raise
        return False
    return True


def test_generated_worlds_need_the_generator():
    if has_generator():
        pytest.skip("the generator is here: see test_the_seed_builds_the_generated_building")
    with pytest.raises(ValueError, match="generator"):
        FindPlaceEnv("generated")


def test_the_seed_builds_the_generated_building():
    if not has_generator():
        pytest.skip("no building generator (sim.world.generator) in this version")
    env = gymnasium.make(MAKE_ID, world="generated", perception="geometric", generator={"size": "small"})
    try:
        first, info = env.reset(seed=3)
        name = env.unwrapped.trial.world.name
        again, info_again = env.reset(seed=3)
        assert env.unwrapped.trial.world.name == name and info_again["goal"] == info["goal"]
        assert np.array_equal(first["laser"], again["laser"]) and np.array_equal(first["goal"], again["goal"])
        env.reset(seed=4)
        assert env.unwrapped.trial.world.name != name
    finally:
        env.close()


@pytest.mark.slow
def test_our_navigator_finds_the_kingfisher_through_the_env_as_far_as_a_trial():
    env = gymnasium.make(MAKE_ID, world="zoo", goal="Kingfisher", perception="geometric")
    obs, _ = env.reset(seed=0)
    policy = env.unwrapped.navigator_policy()
    terminated = truncated = False
    while not (terminated or truncated):
        obs, _, terminated, truncated, info = env.step(policy(obs))
    env.close()
    trial = run_trial("zoo", "Kingfisher", perception="geometric")
    assert terminated and info["distance_m"] == pytest.approx(trial.distance_m, rel=0.05)
