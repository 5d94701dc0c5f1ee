"""The study's comparison: the paper's Table I extended, a box plot like its Fig. 11, path pictures.

Reference results come from the world folder's ``paper_trials.csv``
(``goal,navigator,trial,distance_m``; navigator "human" or "robot"), copied
from the paper's data. Improvement is ``1 - ours / theirs`` as in the paper.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sim.experiments.pictures import draw_floorplan, draw_path, draw_tags
from sim.experiments.study import slug
from sim.world.data import World
from sim.world.oracle import OraclePath


@dataclass(frozen=True)
class GoalRow:
    goal: str
    human: list[float]
    paper_robot: list[float]
    ours: list[float]  # distances of successful trials
    failures: int
    oracle_m: float | None


def load_reference(world: World) -> dict[str, dict[str, list[float]]]:
    """goal -> navigator -> distances (m) from the world's paper_trials.csv, if present."""
    path = world.root / "paper_trials.csv"
    table: dict[str, dict[str, list[float]]] = {}
    if not path.exists():
        return table
    with path.open() as handle:
        for row in csv.DictReader(handle):
            table.setdefault(row["goal"], {}).setdefault(row["navigator"], []).append(float(row["distance_m"]))
    return table


def goal_rows(world: World, records: list[dict[str, Any]], oracles: dict[str, OraclePath]) -> list[GoalRow]:
    reference = load_reference(world)
    rows = []
    for goal in dict.fromkeys(r["goal"] for r in records):
        mine = [r for r in records if r["goal"] == goal]
        ref = reference.get(goal, {})
        rows.append(GoalRow(goal, ref.get("human", []), ref.get("robot", []),
                            [r["distance_m"] for r in mine if r["success"]],
                            sum(1 for r in mine if not r["success"]),
                            oracles[goal].length_m if goal in oracles else None))
    return rows


def _mean(values: list[float]) -> float:
    return float(np.mean(values)) if values else math.nan


def _fmt(value: float, spec: str = ".1f") -> str:
    return "-" if value is None or math.isnan(value) else format(value, spec)


def _ratio(ours: float, oracle: float) -> str:
    return "-" if math.isnan(oracle) or math.isnan(ours) else f"{ours / oracle:.2f}"


def _improvement(ours: float, theirs: float) -> float:
    return (1.0 - ours / theirs) * 100.0 if theirs and not math.isnan(ours) else math.nan


def report_markdown(world: World, rows: list[GoalRow], *, perception: str, trials: int, wall_s: float) -> str:
    """The report: Table I extended with our mean and spread, improvements, oracle and ratio."""
    lines = [
        f"# Study: {world.title}",
        "",
        f"{trials} trial(s) per goal, {perception} perception; study wall time {wall_s / 60:.1f} min.",
        "Improvement is 1 - ours / theirs (positive: we travel less). Ratio is ours / oracle.",
        "",
        "| goal | human mean (m) | paper robot mean (m) | ours mean (m) | ours sd (m) | ok | "
        "vs human (%) | vs paper robot (%) | oracle (m) | ours / oracle |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    totals: dict[str, list[float]] = {"human": [], "robot": [], "ours": [], "oracle": []}
    for row in rows:
        human, robot, ours = _mean(row.human), _mean(row.paper_robot), _mean(row.ours)
        spread = float(np.std(row.ours, ddof=1)) if len(row.ours) > 1 else math.nan
        oracle = row.oracle_m if row.oracle_m is not None else math.nan
        ok = f"{len(row.ours)}/{len(row.ours) + row.failures}"
        lines.append(f"| {row.goal} | {_fmt(human)} | {_fmt(robot)} | {_fmt(ours)} | {_fmt(spread)} | {ok} | "
                     f"{_fmt(_improvement(ours, human))} | {_fmt(_improvement(ours, robot))} | {_fmt(oracle)} | "
                     f"{_ratio(ours, oracle)} |")
        for key, value in (("human", human), ("robot", robot), ("ours", ours), ("oracle", oracle)):
            totals[key].append(value)
    overall = {k: float(np.mean(v)) if v and not any(math.isnan(x) for x in v) else math.nan
               for k, v in totals.items()}
    lines.append(f"| **overall** | {_fmt(overall['human'])} | {_fmt(overall['robot'])} | {_fmt(overall['ours'])} | "
                 f"| | {_fmt(_improvement(overall['ours'], overall['human']))} | "
                 f"{_fmt(_improvement(overall['ours'], overall['robot']))} | {_fmt(overall['oracle'])} | "
                 f"{_ratio(overall['ours'], overall['oracle'])} |")
    failures = [row for row in rows if row.failures]
    if failures:
        lines += ["", "Failed trials are left out of the means: " +
                  ", ".join(f"{r.goal} {r.failures}" for r in failures) + " (reasons in trials.csv)."]
    return "\n".join(lines) + "\n"


def comparison_plot(rows: list[GoalRow], path: str | os.PathLike[str]) -> None:
    """Per goal: boxes of humans, the paper's robot and ours (distance, m), the oracle marked."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 7))
    colours = {"human": "tab:red", "paper robot": "tab:blue", "ours": "tab:green"}
    ticks, labels = [], []
    for i, row in enumerate(rows):
        base = 4.0 * (len(rows) - i)
        series = {"human": row.human, "paper robot": row.paper_robot, "ours": row.ours}
        for j, (name, values) in enumerate(series.items()):
            if not values:
                continue
            box = ax.boxplot([values], positions=[base + 1 - j], orientation="horizontal", widths=0.7,
                             patch_artist=True, whis=(0, 100))
            box["boxes"][0].set(facecolor=colours[name], alpha=0.35, edgecolor=colours[name])
        if row.oracle_m is not None:
            ax.plot([row.oracle_m] * 2, [base - 1.5, base + 1.5], color="black", ls="--", lw=1.2)
        ticks.append(base)
        labels.append(row.goal)
    for name, colour in colours.items():
        ax.plot([], [], "s", color=colour, alpha=0.5, label=name)
    ax.plot([], [], "--", color="black", label="oracle")
    ax.set_yticks(ticks, labels)
    ax.set_xlabel("distance travelled (m)")
    ax.grid(axis="x", alpha=0.3)
    ax.legend(loc="lower right")
    ax.set_title("Finding goals in the zoo: humans, the paper's robot, ours")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def path_pictures(world: World, records: list[dict[str, Any]], oracles: dict[str, OraclePath],
                  folder: Path) -> list[Path]:
    """One picture per goal: every trial's path over the floor plan, and the oracle's."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for goal in dict.fromkeys(r["goal"] for r in records):
        fig, ax = plt.subplots(figsize=(12, 7.5))
        draw_floorplan(ax, world)
        draw_tags(ax, world, goal_tags=[t.id for t in world.label_tags(goal)])
        mine = [r for r in records if r["goal"] == goal and r.get("trajectory")]
        palette = plt.get_cmap("viridis")(np.linspace(0.1, 0.85, max(1, len(mine))))
        for record, colour in zip(mine, palette):
            verdict = f"{record['distance_m']:.1f} m" if record["success"] else "failed"
            draw_path(ax, np.array(record["trajectory"]), colour="tab:red" if not record["success"] else colour,
                      label=f"seed {record['seed']}: {verdict}")
        if goal in oracles:
            oracle = oracles[goal].path
            ax.plot(oracle[:, 0], oracle[:, 1], color="black", ls="--", lw=1.5,
                    label=f"oracle: {oracles[goal].length_m:.1f} m")
        x0, x1, y0, y1 = world.floorplan.extent
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        ax.set_title(f"{world.title}: paths to the {goal}")
        ax.legend(loc="lower right", fontsize=7)
        fig.tight_layout()
        path = folder / f"{slug(goal)}.png"  # a safe name: a goal's text never leaves the folder
        fig.savefig(path, dpi=100)
        plt.close(fig)
        written.append(path)
    return written
