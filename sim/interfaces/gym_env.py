"""``AbstractMap/FindPlace-v0``: find a named place in a building, as a Gymnasium environment.

One step is one control tick of a :class:`~sim.experiments.trial.Trial`
(0.1 s simulated): the action drives the wheels, then the robot senses. The
laser is scanned every step (the trial's mapping rate is raised to its control
rate), tags are read at the perception rate (other steps report none).

- action ``"twist"``: (v m/s, omega rad/s); ``"wheels"``: (left, right) wheel rim speeds, m/s; float64. The
  robot holds to its limits (0.4 m/s, 0.4 rad/s) whatever the wheels are asked.
- observation: see :mod:`sim.interfaces.observation`.
- reward: minus the metres driven this step, plus ``goal_bonus`` on the step the goal's label is read.
- ``terminated`` when the goal's label is read (on the first step, when it is read from the start);
  ``truncated`` at the cap on simulated time (or distance).
- ``reset(seed=...)`` picks the goal (when not given) and seeds the trial's variation; with ``world="generated"``
  it also builds a building from the seed. The same seed gives the same episode.
- ``render_mode="rgb_array"``: the trial's picture so far (floor plan, path, tags read, imagined places).

The environment's own abstract map listens to the tags read, so ``goal``
follows the cues whoever drives; its exploration factor never grows (no one
judges an agent's arrival at the imagined goal; our navigator as a policy keeps
its own abstract map, which does). ``navigator`` defaults to ``paper``, not the
trial's default ``guided``: the observation carries no plates seen from afar
(:mod:`sim.perception.spotting`), which ``guided`` takes in, so through the
environment it would not drive as it does in a trial. Tag ids index
the world's tag table (``env.unwrapped.world.tags``); ``info["cues"]`` gives the
text of the tags read this step.
"""

from __future__ import annotations

import importlib
import shutil
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from sim.experiments.trial import Trial, TrialParams
from sim.interfaces.observation import Observation
from sim.interfaces.policy import NavigatorPolicy
from sim.world.data import World, load_world
from sim.world.robot import RobotParams

GENERATED = "generated"
GYM_CONTROL_HZ = 10.0  # Hz: one step is 0.1 s simulated, the rate agents commonly act at (trials run at 5 Hz)


def _twist(action: np.ndarray, robot: RobotParams) -> tuple[float, float]:
    return float(action[0]), float(action[1])


def _wheels(action: np.ndarray, robot: RobotParams) -> tuple[float, float]:
    left, right = float(action[0]), float(action[1])
    return (left + right) / 2.0, (right - left) / robot.wheel_separation


ACTIONS = {"twist": _twist, "wheels": _wheels}
"""Action kinds: each turns the action into the robot's (v m/s, omega rad/s)."""


def action_space(kind: str, robot: RobotParams) -> spaces.Box:
    """The action space of ``kind`` within the robot's limits."""
    if kind == "twist":
        high = np.array([robot.max_speed, robot.max_turn])
    else:  # each wheel's rim: driving at full speed while turning at the full rate
        high = np.full(2, robot.max_speed + robot.max_turn * robot.wheel_separation / 2.0)
    return spaces.Box(-high, high, (2,), np.float64)


class FindPlaceEnv(gymnasium.Env):
    """Find ``goal`` (or a goal of the world, drawn at each reset) in ``world`` from its signs and labels."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, world: str | World = "zoo", goal: str | None = None, perception: str = "geometric", *,
                 action: str = "twist", navigator: str = "paper", params: TrialParams | None = None,
                 tag_slots: int = 8, goal_bonus: float = 10.0, generator: dict[str, Any] | None = None,
                 render_mode: str | None = None) -> None:
        if action not in ACTIONS:
            raise ValueError(f"action {action!r}: expected one of {sorted(ACTIONS)}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode {render_mode!r}: expected one of {self.metadata['render_modes']} or None")
        if tag_slots < 1:
            raise ValueError(f"tag_slots must be at least 1, got {tag_slots}")
        base = params or replace(TrialParams(), control_hz=GYM_CONTROL_HZ)
        self.params = replace(base, mapping_hz=base.control_hz)  # a fresh scan in every observation
        self.generator = dict(generator or {})
        self._generated: Path | None = None
        if world == GENERATED:
            self._generate = _generator()  # fails now, not at the first reset, when it is missing
            self.world: World | None = None
        else:
            self.world = world if isinstance(world, World) else load_world(world)
            if goal is not None and goal not in self.world.goals and not self.world.label_tags(goal):
                raise ValueError(f"goal {goal!r}: no label in world {self.world.name!r}; "
                                 f"study goals: {sorted(self.world.goals)}")
        self.goal, self.perception, self.navigator = goal, perception, navigator
        self.action_kind, self.goal_bonus, self.render_mode = action, float(goal_bonus), render_mode
        self.robot_params = RobotParams()
        self.layout = Observation(tag_slots, self.params.laser)
        self.observation_space = self.layout.space()
        self.action_space = action_space(action, self.robot_params)
        self.trial: Trial | None = None
        self.tick_s = 1.0 / self.params.control_hz

    # -- the episode -----------------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[dict, dict]:
        super().reset(seed=seed)
        self._end_trial()
        rng = self.np_random
        world = self.world if self.world is not None else self._build(int(rng.integers(2**31 - 1)))
        goal = (options or {}).get("goal") or self.goal
        if goal is None:
            names = sorted(world.goals)
            if not names:
                raise ValueError(f"world {world.name!r} lists no goals: pass goal=")
            goal = names[int(rng.integers(len(names)))]
        self.trial = Trial(world, goal, seed=int(rng.integers(2**31 - 1)), perception=self.perception,
                           navigator=self.navigator, params=self.params)
        self.tick_s = self.trial.tick
        return self._observe(), self._info()

    def step(self, action: np.ndarray) -> tuple[dict, float, bool, bool, dict]:
        trial = self._trial()
        action = np.asarray(action, dtype=np.float64).reshape(2)
        if not np.all(np.isfinite(action)):
            raise ValueError(f"action {action!r}: expected two finite numbers")
        action = np.clip(action, self.action_space.low, self.action_space.high)
        before = trial.distance
        if not trial.done:
            trial.step(ACTIONS[self.action_kind](action, self.robot_params))
        reward = -(trial.distance - before) + (self.goal_bonus if trial.success else 0.0)
        return self._observe(), float(reward), trial.success, trial.done and not trial.success, self._info()

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array":
            return None
        from sim.experiments.pictures import trajectory_image

        trial = self._trial()
        return trajectory_image(trial.result(), trial.world)

    def close(self) -> None:
        self._end_trial()
        if self._generated is not None:
            shutil.rmtree(self._generated, ignore_errors=True)
            self._generated = None

    def navigator_policy(self, *, seed: int = 0) -> NavigatorPolicy:
        """Our navigator as a policy for this episode (call after :meth:`reset`): ``action = policy(obs)``."""
        trial = self._trial()
        return NavigatorPolicy(trial.world, trial.goal, params=self.params, navigator=self.navigator,
                               action=self.action_kind, tick_s=trial.tick, seed=seed)

    # -- helpers ---------------------------------------------------------------------------------

    def _trial(self) -> Trial:
        if self.trial is None:
            raise gymnasium.error.ResetNeeded("call reset() before step(), render() or navigator_policy()")
        return self.trial

    def _end_trial(self) -> None:
        if self.trial is not None:
            self.trial.close()
            self.trial = None

    def _observe(self) -> dict[str, Any]:
        trial = self._trial()
        return self.layout.encode(scan=trial.scan, sightings=trial.sightings, true_pose=trial.last,
                                  odometry=trial.robot.pose(), goal_xy=_imagined_goal(trial))

    def _info(self) -> dict[str, Any]:
        trial = self._trial()
        tags = trial.world.tags
        return {"goal": trial.goal, "sim_s": trial.t, "distance_m": trial.distance, "reason": trial.reason,
                "cues": {s.tag_id: tags[s.tag_id].text for s in trial.sightings if s.tag_id in tags}}

    def _build(self, seed: int) -> World:
        """A generated building from ``seed`` (``generator`` gives its style, size, signage), written to a folder
        of this env's until it closes."""
        if self._generated is None:
            self._generated = Path(tempfile.mkdtemp(prefix="abstract-map-gym-"))
        return load_world(self._generate(seed, root=self._generated, **self.generator))


def _imagined_goal(trial: Trial) -> tuple[float, float]:
    """Where the trial's navigator imagines the goal (its target, for a policy without an abstract map)."""
    model = getattr(getattr(trial.policy, "nav", None), "model", None)
    if model is not None:
        x, y = model.goal_estimate()
    else:
        x, y = trial.policy.picture()[1]
    return float(x), float(y)


def _generator() -> Any:
    """The building generator (``sim.world.generator.generated_world``), or a clear error when absent."""
    try:
        module = importlib.import_module("sim.world.generator")
    except ModuleNotFoundError as exc:
        if exc.name is not None and exc.name.startswith("sim"):
            raise ValueError(f'world "{GENERATED}" needs the building generator (sim.world.generator), which this '
                             "version does not have; pass a world name or folder") from exc
        raise
    return module.generated_world


__all__ = ["ACTIONS", "FindPlaceEnv", "action_space"]
