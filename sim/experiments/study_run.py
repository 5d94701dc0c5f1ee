"""A whole study from its settings: build the worlds, plan the trials, run them, write the report.

:func:`conduct_study` is the Python API behind ``abstract-map study`` and
``benchmarks/run.py generalise``. Outputs in ``out``: ``settings.json``,
``worlds/`` (generated buildings), ``trials/`` (one JSON per trial),
``trials.csv``, ``report.md``, ``worst/`` (the ten worst trials' paths),
``study.json`` (wall time, workers) and, for worlds with the paper's data
(``paper_trials.csv``: the zoo), the paper's Table I extended, ``comparison.png``
and ``paths/GOAL.png``.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from multiprocessing import get_context
from pathlib import Path
from typing import Any

from sim.experiments.study import (
    StudySettings,
    TrialSpec,
    check_settings,
    make_executor,
    one_thread_per_worker,
    plan_specs,
    run_study,
    slug,
    world_oracles,
    write_atomic,
)
from sim.experiments.trial import TrialParams
from sim.experiments.world_spec import GeneratedSpec, generated_folder, parse_world_spec, resolve_worlds
from sim.world.data import World, load_world

Progress = Callable[[int, int, dict[str, Any] | None], None]


@dataclass
class StudyOutcome:
    records: list[dict[str, Any]]
    report: str  # report.md's text
    wall_s: float  # s, this run (trials done before a resume not counted)


def build_worlds(settings: StudySettings, out: Path, *, workers: int = 1) -> list[World]:
    """Every world of ``settings.worlds`` loaded; generated buildings written under ``out/worlds`` first."""
    specs = [parse_world_spec(text) for text in settings.worlds]

    def build(todo: list[GeneratedSpec], root: Path) -> list[Path]:
        missing = [g for g in todo if not (_folder_name(g, root) / "world.json").is_file()]
        if len(missing) > 1 and workers > 1:
            from tqdm import tqdm

            with one_thread_per_worker(), ProcessPoolExecutor(min(workers, len(missing)),
                                                              mp_context=get_context("spawn")) as pool:
                list(tqdm(pool.map(generated_folder, missing, [root] * len(missing)), total=len(missing),
                          desc="building worlds", unit="world", file=sys.stderr, dynamic_ncols=True))
        return [generated_folder(g, root) for g in todo]

    folders = resolve_worlds(specs, out / "worlds", build=build)
    worlds = [load_world(folder) for folder in folders]
    names: dict[str, Path] = {}
    for world in worlds:
        if names.setdefault(world.name, world.root) != world.root:
            raise ValueError(f"two worlds are named {world.name!r} ({names[world.name]} and {world.root}); "
                             "a study keys trials by world name")
    return worlds


def _folder_name(spec: GeneratedSpec, root: Path) -> Path:
    from sim.world.generator import world_name

    return root / world_name(spec.seed, spec.style, spec.size, spec.signage, spec.arrows)


def plan_study(worlds: list[World], settings: StudySettings) -> list[TrialSpec]:
    """Every world x goal x navigator x seed; ``settings.goals`` filters goals (each must be in some world)."""
    if settings.goals is not None:
        unknown = [g for g in settings.goals if not any(g in w.goals for w in worlds)]
        if unknown:
            known = sorted({g for w in worlds for g in w.goals})[:20]
            raise ValueError(f"--goals: {unknown} in none of the worlds; goals include {known}")
    per_world: list[list[TrialSpec]] = []
    for world in worlds:
        goals = [g for g in world.goals if settings.goals is None or g in settings.goals]
        if goals:
            per_world.append(plan_specs(world, settings.trials, settings.perception, goals=goals,
                                        base=TrialParams(max_sim_s=settings.max_sim_s),
                                        navigators=settings.navigators, oracle_m=world_oracles(world, goals)))
    # Round robin over worlds (each world's first goal and seed for every navigator, then the next...), so
    # the trials finished when a long study is stopped early spread over every world, style and signage level.
    navigators = {name: k for k, name in enumerate(dict.fromkeys(settings.navigators))}
    order = []
    for w, specs in enumerate(per_world):
        goals = {goal: k for k, goal in enumerate(dict.fromkeys(spec.goal for spec in specs))}
        order += [((spec.seed, goals[spec.goal], w, navigators[spec.navigator]), spec) for spec in specs]
    return [spec for _, spec in sorted(order, key=lambda pair: pair[0])]


def write_outputs(out: Path, records: list[dict[str, Any]], worlds: list[World], settings: StudySettings,
                  wall_s: float) -> str:
    """report.md (and the pictures it links); returns its text."""
    from sim.experiments.habits import habits_table, study_habits
    from sim.experiments.report import comparison_plot, goal_rows, load_reference, path_pictures, report_markdown
    from sim.experiments.summary import summary_markdown, worst_pictures, worst_trials
    from sim.world.oracle import oracle_paths

    by_name = {w.name: w for w in worlds}
    navigators = list(dict.fromkeys(r.get("navigator", "paper") for r in records))
    blocks: list[str] = []
    first = True
    for world in worlds:
        if not load_reference(world):
            continue
        mine = [r for r in records if r.get("world") == world.name]
        goals = list(dict.fromkeys(r["goal"] for r in mine))
        oracles = oracle_paths(world, goals) if goals else {}
        for navigator in navigators:
            theirs = [r for r in mine if r.get("navigator", "paper") == navigator]
            if not theirs:
                continue
            suffix = "" if first else f"-{slug(world.name)}-{slug(navigator)}"
            rows = goal_rows(world, theirs, oracles)
            text = report_markdown(world, rows, perception=settings.perception, trials=settings.trials, wall_s=wall_s)
            if not first or len(navigators) > 1:
                text = text.replace(f"# Study: {world.title}", f"## {world.title} against the paper "
                                                               f"(navigator {navigator})", 1)
            blocks.append(text)
            comparison_plot(rows, out / f"comparison{suffix}.png")
            path_pictures(world, theirs, oracles, out / f"paths{suffix}")
            reference = world.root / "paper_trials.csv"
            write_atomic(out / "paper_trials.csv", reference.read_text())
            first = False
    if not blocks or not blocks[0].startswith("# "):
        titles = ", ".join(settings.worlds)
        blocks.insert(0, f"# Study: {titles}\n\n{settings.trials} trial(s) per goal and navigator, "
                         f"{settings.perception} perception, navigators {', '.join(settings.navigators)}, "
                         f"{len(worlds)} world(s); wall time {wall_s / 60:.1f} min.\n")
    worst = worst_trials(records)
    pictures = worst_pictures(worst, by_name, out / "worst")
    moved, unmeasured = study_habits(records, by_name, lambda r: r.get("signage") or "-")
    habits = habits_table(moved, "signage") if moved else []
    if unmeasured:
        habits += ["", f"{unmeasured} trial(s) carried no walk to measure (no trajectory, or a world not loaded)."]
    blocks.append(summary_markdown(records, worst=worst, pictures=pictures, relative_to=out, habits=habits))
    report = "\n".join(blocks)
    write_atomic(out / "report.md", report)
    return report


def conduct_study(settings: StudySettings, out: Path, *, workers: int = 2, executor: str = "process",
                  address: str | None = None, progress: Progress | None = None, log: bool = False) -> StudyOutcome:
    """Run (or resume) the study ``settings`` in ``out`` and write its report.

    Raises :class:`sim.experiments.study.StudyError` when ``out`` holds another study, and ValueError
    (or its subclasses WorldSpecError, WorldError) on bad settings, before any trial runs.
    """
    for text in settings.worlds:
        parse_world_spec(text)  # every spec checked before anything is written
    from sim.navigation.policies import NAVIGATORS

    unknown = [n for n in settings.navigators if n not in NAVIGATORS]
    if unknown or not settings.navigators:
        raise ValueError(f"--navigator {', '.join(unknown) or '(none)'}: expected some of {', '.join(NAVIGATORS)}")
    check_settings(out, settings, record=False)  # refuse another study's folder before writing anything
    began = time.perf_counter()
    worlds = build_worlds(settings, out, workers=workers)
    specs = plan_study(worlds, settings)
    if log:  # a rerun recording of each trial beside its record: trials/WORLD/KEY.rrd
        specs = [replace(spec, log_dir=str(out / "trials")) for spec in specs]
    check_settings(out, settings)  # recorded only once the settings proved good
    records = run_study(specs, out, executor=make_executor(executor, workers, address), progress=progress)
    wall = time.perf_counter() - began
    report = write_outputs(out, records, worlds, settings, wall)
    write_atomic(out / "study.json", json.dumps({**settings.to_dict(), "workers": workers, "executor": executor,
                                                 "trials_run": len(records), "wall_s": round(wall, 1)}, indent=1))
    return StudyOutcome(records, report, wall)
