"""Time every settle of the Lion replay in this process: one JSON line on stdout.

Run by ``benchmarks/run.py settle`` with ``PYTHONPATH`` pointing at the checkout to measure; it uses only
the model API that every version since the replay was written shares (load_scenario, from_hierarchy,
observe_tag, set_explored_centre, settle, goal_estimate), so it measures old and new code alike.

    python benchmarks/lion_settles.py REPLAY_JSON [RUNS]
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np


def main() -> int:
    import abstract_map
    from abstract_map.model import AbstractMap
    from abstract_map.scenario import load_scenario

    scenario = load_scenario(sys.argv[1])
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    cpu: list[list[float]] = []
    for _ in range(runs):
        model = AbstractMap.from_hierarchy(scenario.hierarchy, scenario.start, goal=scenario.goal)
        visited = [np.array(scenario.start[:2])]
        model.set_explored_centre(visited[0])
        model.settle()
        times, steps, settled = [], [], []
        for step in scenario.steps:
            model.observe_tag(step.tag, step.text, step.pose, kind=step.kind)
            visited.append(np.array(step.pose[:2]))
            model.set_explored_centre(np.mean(visited, axis=0))
            began = time.process_time()
            report = model.settle()
            times.append(time.process_time() - began)
            steps.append(report.iterations)
            settled.append(bool(report.settled))
        cpu.append(times)
    print(json.dumps({"module": abstract_map.__file__, "cpu_s": cpu, "steps": steps, "settled": settled,
                      "goal": [float(v) for v in model.goal_estimate()]}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
