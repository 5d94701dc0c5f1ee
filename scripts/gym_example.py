"""Run a random agent and our navigator through the Gymnasium environment, and compare them (no training).

  python scripts/gym_example.py --world zoo --goal Kingfisher --seed 0 [--max-steps 3000]

Each agent gets the same seeded episode; the script prints, per agent, whether
it read the goal's label, the return, the metres driven and the simulated
seconds. Needs the sim and gym extras: pip install -e ".[sim,gym]".
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

ENV = "sim.interfaces:AbstractMap/FindPlace-v0"  # gymnasium imports sim.interfaces, which registers the id


def episode(env: gymnasium.Env, choose: Callable[[dict[str, Any]], np.ndarray], seed: int, max_steps: int,
            name: str) -> dict[str, Any]:
    """One episode with ``choose(obs) -> action``; stops at the env's end or after ``max_steps``."""
    obs, info = env.reset(seed=seed)
    began, total = time.perf_counter(), 0.0
    terminated = truncated = False
    for _ in tqdm(range(max_steps), desc=name, unit="step", leave=False):
        obs, reward, terminated, truncated, info = env.step(choose(obs))
        total += reward
        if terminated or truncated:
            break
    return {"agent": name, "found": terminated, "return": total, "distance_m": info["distance_m"],
            "sim_s": info["sim_s"], "wall_s": time.perf_counter() - began,
            "end": info["reason"] or f"step cap of {max_steps} reached"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--world", default="zoo")
    parser.add_argument("--goal", default="Kingfisher")
    parser.add_argument("--perception", default="geometric", choices=["geometric", "camera"])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-steps", type=int, default=3000, help="steps per agent (0.1 s simulated each)")
    args = parser.parse_args()

    env = gymnasium.make(ENV, world=args.world, goal=args.goal, perception=args.perception)
    env.action_space.seed(args.seed)
    rows = [episode(env, lambda obs: env.action_space.sample(), args.seed, args.max_steps, "random")]
    env.reset(seed=args.seed)
    ours = env.unwrapped.navigator_policy()  # built for this episode's world and goal; it counts its own steps
    rows.append(episode(env, ours, args.seed, args.max_steps, "ours"))
    env.close()
    for row in rows:
        print(f"{row['agent']:>6}: {'found' if row['found'] else 'not found':9} return {row['return']:7.1f}, "
              f"{row['distance_m']:5.1f} m, {row['sim_s']:6.1f} s simulated in {row['wall_s']:5.1f} s wall "
              f"({row['end']})")


if __name__ == "__main__":
    main()
