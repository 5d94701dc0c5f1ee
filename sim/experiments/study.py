"""A study: every goal of a world, N trials each, on a local process pool or a Ray cluster.

Trials differ by seed. A seed draws the start pose's jitter (std 0.10 m and 3
degrees) and the recovery manoeuvre's turning direction; in geometric mode it
also draws detection noise (std 0.03 m and 1 degree per sighting), while the
camera mode's noise is the detector's own. Odometry is perfect, as in the
paper's study. Each finished trial is written to ``DIR/trials/GOAL-SEED.json``
at once, so an interrupted study run again skips what is done; a trial that
raises is recorded with its error as the reason and does not stop the rest.
"""

from __future__ import annotations

import csv
import json
import os
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from sim.experiments.trial import TrialParams
from sim.world.data import World

CSV_FIELDS = ["goal", "seed", "perception", "success", "reason", "distance_m", "sim_s", "wall_s"]


@dataclass(frozen=True)
class TrialSpec:
    """Everything one worker needs to run one trial (picklable)."""

    world: str  # path of the world folder
    goal: str
    seed: int
    perception: str
    params: TrialParams
    log_dir: str | None = None  # folder for a rerun recording of the trial (KEY.rrd), or none

    @property
    def key(self) -> str:
        return f"{self.goal.replace(' ', '_')}-{self.seed}"


def study_params(perception: str, base: TrialParams | None = None) -> TrialParams:
    """The per-trial variation of a study (see the module docstring)."""
    params = replace(base or TrialParams(), start_jitter_m=0.10, start_jitter_deg=3.0)
    if perception == "geometric":
        params = replace(params, detection_noise_m=0.03, detection_noise_deg=1.0)
    return params


def run_spec(spec: TrialSpec) -> dict[str, Any]:
    """Run one trial; never raises: an error becomes a failed row with the error as its reason."""
    began = time.perf_counter()
    try:
        from sim.experiments.trial import run_trial

        log = None if spec.log_dir is None else Path(spec.log_dir) / f"{spec.key}.rrd"
        result = run_trial(spec.world, spec.goal, seed=spec.seed, perception=spec.perception, params=spec.params,
                           log=log)
        return result.to_dict()
    except Exception as exc:  # a failed trial is data, not a crash of the study
        return {"goal": spec.goal, "seed": spec.seed, "perception": spec.perception, "success": False,
                "reason": f"error: {type(exc).__name__}: {exc}", "distance_m": float("nan"), "sim_s": 0.0,
                "wall_s": round(time.perf_counter() - began, 2), "traceback": traceback.format_exc()}


class ProcessExecutor:
    """A local pool of worker processes."""

    def __init__(self, workers: int, address: str | None = None) -> None:
        if address is not None:
            raise ValueError("--address is only for the ray executor")
        self.workers = max(1, workers)

    def map_unordered(self, fn: Callable[[TrialSpec], dict[str, Any]],
                      specs: list[TrialSpec]) -> Iterator[tuple[TrialSpec, dict[str, Any]]]:
        if self.workers == 1:
            for spec in specs:
                yield spec, fn(spec)
            return
        from concurrent.futures import ProcessPoolExecutor, as_completed
        from multiprocessing import get_context

        with ProcessPoolExecutor(self.workers, mp_context=get_context("spawn")) as pool:
            futures = {pool.submit(fn, spec): spec for spec in specs}
            for future in as_completed(futures):
                yield futures[future], future.result()


class RayExecutor:
    """Trials as Ray tasks: a local Ray instance, or the cluster at ``address``."""

    def __init__(self, workers: int, address: str | None = None) -> None:
        try:
            import ray
        except ImportError as exc:
            raise ValueError('the ray executor needs Ray: pip install "abstract-map[ray]"') from exc
        self.ray = ray
        if not ray.is_initialized():
            if address:
                ray.init(address=address, log_to_driver=False)
            else:
                ray.init(num_cpus=max(1, workers), include_dashboard=False, log_to_driver=False)

    def map_unordered(self, fn: Callable[[TrialSpec], dict[str, Any]],
                      specs: list[TrialSpec]) -> Iterator[tuple[TrialSpec, dict[str, Any]]]:
        remote = self.ray.remote(num_cpus=1)(fn)
        pending = {remote.remote(spec): spec for spec in specs}
        while pending:
            ready, _ = self.ray.wait(list(pending), num_returns=1)
            for ref in ready:
                yield pending.pop(ref), self.ray.get(ref)


EXECUTORS: dict[str, type[ProcessExecutor] | type[RayExecutor]] = {"process": ProcessExecutor, "ray": RayExecutor}


def make_executor(name: str, workers: int, address: str | None = None) -> ProcessExecutor | RayExecutor:
    if name not in EXECUTORS:
        raise ValueError(f"executor {name!r}: expected one of {sorted(EXECUTORS)}")
    return EXECUTORS[name](workers, address)


def plan_specs(world: World, trials: int, perception: str, *, base: TrialParams | None = None,
               goals: Iterable[str] | None = None) -> list[TrialSpec]:
    """Every goal x ``trials`` seeds, goals in the world's order."""
    params = study_params(perception, base)
    chosen = list(goals) if goals is not None else list(world.goals)
    return [TrialSpec(str(world.root), goal, seed, perception, params) for goal in chosen for seed in range(trials)]


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def run_study(world: World, specs: list[TrialSpec], out: Path, *, executor: ProcessExecutor | RayExecutor,
              progress: Callable[[int, int, dict[str, Any] | None], None] | None = None) -> list[dict[str, Any]]:
    """Run the specs not yet done in ``out/trials``; return every trial's record (done before or now)."""
    folder = out / "trials"
    folder.mkdir(parents=True, exist_ok=True)
    todo = [s for s in specs if not (folder / f"{s.key}.json").exists()]
    done = len(specs) - len(todo)
    if progress:
        progress(done, len(specs), None)
    for spec, record in executor.map_unordered(run_spec, todo):
        _write_atomic(folder / f"{spec.key}.json", json.dumps(record))
        done += 1
        if progress:
            progress(done, len(specs), record)
    records = [json.loads((folder / f"{s.key}.json").read_text()) for s in specs]
    write_csv(records, out / "trials.csv")
    return records


def write_csv(records: list[dict[str, Any]], path: Path) -> None:
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=CSV_FIELDS, extrasaction="ignore")
        writer.writeheader()
        for record in sorted(records, key=lambda r: (r["goal"], r["seed"])):
            writer.writerow({k: record.get(k) for k in CSV_FIELDS})

