"""A study: every goal of one or more worlds, N trials each per navigator, on a process pool or Ray.

Trials differ by seed. A seed draws the start pose's jitter (std 0.10 m and 3
degrees) and the recovery manoeuvre's turning direction; in geometric mode it
also draws detection noise (std 0.03 m and 1 degree per sighting), while the
camera mode's noise is the detector's own. Odometry is perfect, as in the
paper's study. A trial is keyed by (world, navigator, goal, seed) and written
to ``DIR/trials/WORLD/NAVIGATOR-GOAL-SEED-HASH.json`` (names made safe, the
hash keeping "Polar bear" and "Polar_bear" apart) at once and atomically, so
an interrupted study run again skips what is done, across worlds; a trial that
raises is recorded with its error as the reason and does not stop the rest.
``DIR/settings.json`` records the study's settings; a resume with other
settings is refused (:class:`StudyError`).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import re
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from abstract_map.files import write_text_atomic
from sim.experiments.metrics import oracle_ratio, spl
from sim.experiments.trial import TrialParams
from sim.navigation.names import DEFAULT_NAVIGATOR
from sim.world.data import World

CSV_FIELDS = ["world", "style", "signage", "navigator", "goal", "role", "seed", "perception", "success", "reason",
              "explanation", "distance_m", "oracle_m", "spl", "near_at_m", "seen_at_m", "sim_s", "wall_s", "cpu_s"]
SETTINGS_FILE = "settings.json"
SETTINGS_FORMAT = "abstract-map-study/2"


class StudyError(ValueError):
    """A study folder that cannot be used for the study asked for."""


def slug(text: str, limit: int = 40) -> str:
    """A file-name-safe form of ``text``: letters, digits, '.', '-' and '_' only, never empty or dots alone."""
    cleaned = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._")[:limit]
    return cleaned or "_"


@dataclass(frozen=True)
class TrialSpec:
    """Everything one worker needs to run one trial and label its record (picklable)."""

    world: str  # path of the world folder
    goal: str
    seed: int
    perception: str
    params: TrialParams
    navigator: str = DEFAULT_NAVIGATOR
    world_name: str = ""  # the world's name (default: the folder's name)
    oracle_m: float | None = None  # m, the oracle's length from the (un-jittered) start
    style: str = ""  # a generated world's style and signage level ("" for others)
    signage: str = ""
    role: str = ""  # why the generator chose this goal (world.json's ``goal_roles``: "hall", "dead end", ...;
    # "" for others)

    @property
    def name(self) -> str:
        return self.world_name or Path(self.world).name
    log_dir: str | None = None  # folder for a rerun recording of the trial (KEY.rrd), or none

    @property
    def key(self) -> str:
        """The trial's file, relative to ``trials/``: safe and unique per (world, navigator, goal, seed)."""
        identity = json.dumps([self.name, self.navigator, self.goal, self.seed])
        digest = hashlib.sha1(identity.encode()).hexdigest()[:8]
        return f"{slug(self.name, 80)}/{slug(self.navigator, 20)}-{slug(self.goal)}-{self.seed}-{digest}"


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
        result = run_trial(spec.world, spec.goal, seed=spec.seed, perception=spec.perception,
                           navigator=spec.navigator, params=spec.params, log=log)
        record = result.to_dict()
    except Exception as exc:  # a failed trial is data, not a crash of the study
        record = failed_record(spec, exc, began)
    return label_record(record, spec)


def failed_record(spec: TrialSpec, exc: Exception, began: float) -> dict[str, Any]:
    """The record of a trial that raised ``exc`` (call inside its ``except``): failed, the error as its reason,
    the wall time since ``began`` (``time.perf_counter()``) and the traceback."""
    return {"goal": spec.goal, "seed": spec.seed, "perception": spec.perception, "success": False,
            "reason": f"error: {type(exc).__name__}: {exc}", "distance_m": None, "sim_s": 0.0,
            "wall_s": round(time.perf_counter() - began, 2), "traceback": traceback.format_exc()}


def shares_run(spec: TrialSpec) -> tuple[str, str, int, str, str] | None:
    """Specs with the same key share one run: a goal-blind navigator's path is the same whatever the goal."""
    from sim.navigation.policies import NAVIGATORS

    if not getattr(NAVIGATORS.get(spec.navigator), "goal_blind", False) or spec.log_dir is not None:
        return None
    return spec.world, spec.navigator, spec.seed, spec.perception, json.dumps(asdict(spec.params), sort_keys=True)


def run_unit(unit: tuple[TrialSpec, ...]) -> list[dict[str, Any]]:
    """Run the trials of ``unit`` (specs that share one run, or a single spec); one record per spec, in order.

    A shared run watches every goal of the unit until all are read or a cap is hit; each goal's record is the
    run up to its label's first read (:meth:`sim.experiments.trial.Trial.results`). Never raises.
    """
    if len(unit) == 1:
        return [run_spec(unit[0])]
    began = time.perf_counter()
    first = unit[0]
    try:
        from sim.experiments.trial import Trial

        with Trial(first.world, first.goal, seed=first.seed, perception=first.perception, navigator=first.navigator,
                   params=first.params, also=[s.goal for s in unit[1:]]) as trial:
            while not trial.done:
                trial.step()
            results = trial.results()
            return [label_record(results[spec.goal].to_dict(), spec) for spec in unit]
    except Exception as exc:  # a failed run is data, not a crash of the study
        return [label_record(failed_record(spec, exc, began), spec) for spec in unit]


def label_record(record: dict[str, Any], spec: TrialSpec) -> dict[str, Any]:
    """The record with its study key and scores: world, navigator, style, signage, role, oracle_m, spl, ratio."""
    distance = record.get("distance_m")
    score = spl(record["success"], distance, spec.oracle_m)
    ratio = oracle_ratio(record["success"], distance, spec.oracle_m)
    return {**record, "world": spec.name, "navigator": spec.navigator, "style": spec.style,
            "signage": spec.signage, "role": spec.role, "oracle_m": spec.oracle_m,
            "spl": None if score is None else round(score, 4),
            "oracle_ratio": None if ratio is None else round(ratio, 4)}


Unit = Any  # what an executor maps over: here a tuple of trial specs sharing one run
Result = Any  # what the mapped function returns for one unit


THREAD_POOL_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


@contextmanager
def one_thread_per_worker() -> Iterator[None]:
    """Worker processes started within get one BLAS/OpenMP thread each, unless the caller set a count.

    A study runs one trial per core; a numeric library's own pool in every worker would fight the other workers
    for the same cores. The parent's environment is as it was afterwards.
    """
    unset = [name for name in THREAD_POOL_VARIABLES if name not in os.environ]
    os.environ.update(dict.fromkeys(unset, "1"))
    try:
        yield
    finally:
        for name in unset:
            os.environ.pop(name, None)


class ProcessExecutor:
    """A local pool of worker processes."""

    def __init__(self, workers: int, address: str | None = None) -> None:
        if address is not None:
            raise ValueError("--address is only for the ray executor")
        self.workers = max(1, workers)

    def map_unordered(self, fn: Callable[[Unit], Result], specs: list[Unit]) -> Iterator[tuple[Unit, Result]]:
        if self.workers == 1:
            for spec in specs:
                yield spec, fn(spec)
            return
        from concurrent.futures import ProcessPoolExecutor, as_completed
        from multiprocessing import get_context

        with one_thread_per_worker(), ProcessPoolExecutor(self.workers, mp_context=get_context("spawn")) as pool:
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

    def map_unordered(self, fn: Callable[[Unit], Result], specs: list[Unit]) -> Iterator[tuple[Unit, Result]]:
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
               goals: Iterable[str] | None = None, navigators: Iterable[str] = (DEFAULT_NAVIGATOR,),
               oracle_m: dict[str, float] | None = None) -> list[TrialSpec]:
    """Every goal x navigator x ``trials`` seeds of one world, goals in the world's order."""
    params = study_params(perception, base)
    chosen = list(dict.fromkeys(goals)) if goals is not None else list(world.goals)
    made = world.generator or {}
    oracle_m = oracle_m or {}
    return [TrialSpec(str(world.root), goal, seed, perception, params, navigator=navigator, world_name=world.name,
                      oracle_m=oracle_m.get(goal), style=str(made.get("style", "")),
                      signage=str(made.get("signage", "")), role=str(made.get("goal_roles", {}).get(goal, "")))
            for goal in chosen for navigator in dict.fromkeys(navigators) for seed in range(trials)]


def world_oracles(world: World, goals: Iterable[str]) -> dict[str, float]:
    """The oracle's length (m) per goal: from world.json's ``oracle_m`` when it has them, else searched."""
    wanted = list(dict.fromkeys(goals))
    stored = world.oracle_m or {}
    if all(goal in stored for goal in wanted):
        return {goal: stored[goal] for goal in wanted}
    from sim.world.oracle import oracle_paths

    return {goal: path.length_m for goal, path in oracle_paths(world, wanted).items()}


@dataclass(frozen=True)
class StudySettings:
    """What a study folder's trials were run with; a resume must ask for the same."""

    worlds: tuple[str, ...]  # the --world specs as given
    perception: str
    navigators: tuple[str, ...]
    trials: int  # per goal and navigator
    goals: tuple[str, ...] | None = None  # None: every goal of every world
    max_sim_s: float = TrialParams.max_sim_s  # s of simulated time before a trial fails

    def to_dict(self) -> dict[str, Any]:
        data = json.loads(json.dumps(asdict(self)))
        if self.max_sim_s == TrialParams.max_sim_s:
            del data["max_sim_s"]  # the default is left out, so folders from before the field resume
        return {"format": SETTINGS_FORMAT, **data}


def check_settings(out: Path, settings: StudySettings, *, record: bool = True) -> None:
    """Record ``settings`` in a new study folder (unless not ``record``), or raise :class:`StudyError` if
    the folder holds another study's."""
    path = out / SETTINGS_FILE
    wanted = settings.to_dict()
    if path.exists():
        try:
            recorded = json.loads(path.read_text())
        except (OSError, ValueError) as exc:
            raise StudyError(f"{path}: unreadable ({exc}); use another --out") from None
        if recorded != wanted:
            differ = [k for k in wanted if recorded.get(k) != wanted[k]]
            shown = "; ".join(f"{k} {recorded.get(k)!r} there, {wanted[k]!r} here" for k in differ)
            raise StudyError(f"{out} holds a study with other settings ({shown}); "
                             "resume it with the same settings or use another --out")
        return
    if record:
        write_atomic(path, json.dumps(wanted, indent=1))


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` by a temporary file and a rename (creating its folder): never half-written."""
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, text)


def _load_record(path: Path, spec: TrialSpec) -> dict[str, Any] | None:
    """The finished record of ``spec`` at ``path``, or None when missing, unreadable or another trial's."""
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(record, dict) or "success" not in record:
        return None
    mine = (spec.name, spec.navigator, spec.goal, spec.seed)
    if (record.get("world"), record.get("navigator"), record.get("goal"), record.get("seed")) != mine:
        return None
    return {"role": spec.role, **record}  # a record written before roles were recorded takes its spec's


def run_study(specs: list[TrialSpec], out: Path, *, executor: ProcessExecutor | RayExecutor,
              progress: Callable[[int, int, dict[str, Any] | None], None] | None = None) -> list[dict[str, Any]]:
    """Run the specs not yet done in ``out/trials``; return every trial's record (done before or now).

    Specs of a goal-blind navigator that differ only by goal share one run (:func:`shares_run`). Also writes
    ``out/trials.csv``, one row per trial.
    """
    specs = list({s.key: s for s in specs}.values())
    folder = out / "trials"
    records: dict[str, dict[str, Any]] = {}
    for spec in specs:
        found = _load_record(folder / f"{spec.key}.json", spec)
        if found is not None:
            records[spec.key] = found
    todo = [s for s in specs if s.key not in records]
    if progress:
        progress(len(records), len(specs), None)
    shared: dict[object, list[TrialSpec]] = {}
    for spec in todo:
        shared.setdefault(shares_run(spec) or spec.key, []).append(spec)
    units = [tuple(group) for group in shared.values()]
    for unit, unit_records in executor.map_unordered(run_unit, units):
        for spec, record in zip(unit, unit_records):
            write_atomic(folder / f"{spec.key}.json", json.dumps(record))
            records[spec.key] = record
            if progress:
                progress(len(records), len(specs), record)
    ordered = [records[s.key] for s in specs]
    write_csv(ordered, out / "trials.csv")
    return ordered


def write_csv(records: list[dict[str, Any]], path: Path) -> None:
    """One row per trial (:data:`CSV_FIELDS`), sorted by world, navigator, goal and seed."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=CSV_FIELDS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for record in sorted(records, key=lambda r: (r.get("world", ""), r.get("navigator", ""), r["goal"], r["seed"])):
        writer.writerow({k: record.get(k) for k in CSV_FIELDS})
    write_atomic(path, buffer.getvalue())
