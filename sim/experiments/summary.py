"""A study's summary over many worlds: success, SPL, ratio to the oracle and failures, by group.

Groups: overall, per navigator, style, signage level and world. SPL is
Anderson et al. (2018) (:mod:`sim.experiments.metrics`), averaged over every
trial with a known oracle (a failure scores 0); the ratio to the oracle
(distance / oracle) is averaged over successful trials only. The ten worst
trials (lowest SPL, then longest) get a picture of their path.
"""

from __future__ import annotations

import itertools
import math
import re
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from abstract_map.files import atomic_path
from sim.experiments.diagnosis import KINDS
from sim.experiments.habits import habits_legend
from sim.experiments.pictures import draw_floorplan, draw_path, draw_tags, draw_walk_marks
from sim.experiments.walk import PHASES, phase_means
from sim.world.data import World

Record = dict[str, Any]


def reason_kind(record: Record) -> str:
    """A failure's reason without its particulars (numbers, error messages), for counting."""
    reason = str(record.get("reason", ""))
    if reason.startswith("error:"):
        return ":".join(reason.split(":")[:2]).strip()
    return re.sub(r"\d+(\.\d+)?", "N", reason.split(":")[0]).strip()


def explanation_kind(record: Record) -> str:
    """A failure's explanation without its particulars (a kind of ``sim.experiments.diagnosis.KINDS``); "-" for
    a record made before trials were explained."""
    return str(record.get("explanation") or "-").split(":")[0].strip()


def stats(records: list[Record]) -> dict[str, Any]:
    """Trials, successes, success rate, mean SPL, mean ratio to the oracle, mean distance and wall time."""
    n = len(records)
    found = [r for r in records if r["success"]]
    spls = [r["spl"] for r in records if r.get("spl") is not None]
    ratios = [r["oracle_ratio"] for r in found if r.get("oracle_ratio") is not None]
    distances = [r["distance_m"] for r in found if r.get("distance_m") is not None]
    walls = [r["wall_s"] for r in records if r.get("wall_s") is not None]
    cpus = [r["cpu_s"] for r in records if r.get("cpu_s") is not None and math.isfinite(r["cpu_s"])]
    return {"trials": n, "found": len(found), "success": len(found) / n if n else math.nan,
            "spl": float(np.mean(spls)) if spls else math.nan,
            "ratio": float(np.mean(ratios)) if ratios else math.nan,
            "distance": float(np.mean(distances)) if distances else math.nan,
            "wall": float(np.mean(walls)) if walls else math.nan,
            "cpu": float(np.mean(cpus)) if cpus else math.nan,
            "failures": Counter(reason_kind(r) for r in records if not r["success"])}


@dataclass(frozen=True)
class SeedSpread:
    """How much one navigator's walks depend on the trial's seed alone (the start's jitter, the stuck recovery's
    turning direction and, in geometric mode, the detection noise)."""

    goals: int  # goals (world, goal, perception) run with two seeds or more
    sd: float  # SPL; the pooled standard deviation of one goal's SPL across its seeds
    apart: float  # share of the pairs of seeds of one goal whose SPL differ by more than APART_SPL
    alike: float  # share of those pairs that scored alike (SPL within ALIKE_SPL): the same way, give or take
    # the start's jitter (two seeds' walks never match to the centimetre)

    @property
    def trials_needed(self) -> int:
        """Paired trials for a change of ``RESOLVE_SPL`` to stand at two standard errors, if the change draws
        every walk afresh as a new seed does (a change that moves fewer walks needs fewer)."""
        return math.ceil((2 * math.sqrt(2) * self.sd / RESOLVE_SPL) ** 2)


APART_SPL = 0.1  # SPL; two seeds' walks this far apart took different ways
ALIKE_SPL = 0.005  # SPL; two seeds' walks this close took the same way (0.5 % of the walk)
RESOLVE_SPL = 0.01  # SPL; the change a comparison is asked to resolve (screens gain 0.005-0.02)


def seed_spread(records: list[Record]) -> dict[str, SeedSpread]:
    """Per navigator, over the goals run with two seeds or more: the pooled standard deviation of a goal's SPL
    across seeds and how often two seeds' walks part (:class:`SeedSpread`); navigators with no such goal are
    left out."""
    runs: dict[tuple[str, ...], list[float]] = {}
    for r in records:
        if r.get("spl") is not None:
            key = (r.get("navigator", "paper"), str(r.get("world", "")), r["goal"], str(r.get("perception", "")))
            runs.setdefault(key, []).append(float(r["spl"]))
    out: dict[str, SeedSpread] = {}
    for nav in dict.fromkeys(key[0] for key in runs):
        goals = [np.array(spls) for key, spls in runs.items() if key[0] == nav and len(spls) >= 2]
        if not goals:
            continue
        sd = math.sqrt(sum(float(np.sum((g - g.mean()) ** 2)) for g in goals) / sum(len(g) - 1 for g in goals))
        gaps = np.array([abs(a - b) for g in goals for a, b in itertools.combinations(g, 2)])
        out[nav] = SeedSpread(len(goals), sd, float(np.mean(gaps > APART_SPL)), float(np.mean(gaps <= ALIKE_SPL)))
    return out


def _f(value: float, spec: str = ".2f") -> str:
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) else format(value, spec)


def _row(label: list[str], s: dict[str, Any]) -> str:
    rate = f"{100 * s['success']:.0f}% ({s['found']}/{s['trials']})" if s["trials"] else "-"
    return "| " + " | ".join([*label, rate, _f(s["spl"]), _f(s["ratio"]), _f(s["distance"], ".1f"),
                              _f(s["wall"], ".1f")]) + " |"


def grouped_table(records: list[Record], columns: list[str], key: Callable[[Record], tuple[str, ...]]) -> list[str]:
    """A markdown table of :func:`stats` per group ``key(record)``, groups in first-seen order."""
    groups: dict[tuple[str, ...], list[Record]] = {}
    for record in records:
        groups.setdefault(key(record), []).append(record)
    lines = ["| " + " | ".join([*columns, "success", "SPL", "ratio to oracle", "distance (m)", "wall (s)"]) + " |",
             "|" + " --- |" * (len(columns) + 5)]
    lines += [_row(list(k), stats(v)) for k, v in sorted(groups.items())]
    return lines


WALK_HEADER = ["result", "trials", "walked", "oracle", *PHASES]  # after the group's own columns


def walk_rows(records: list[Record], key: Callable[[Record], tuple[str, ...]]) -> list[list[str]]:
    """Where the walking went (:mod:`sim.experiments.walk`) per group ``key(record)``, found and failed trials
    apart: the group, "found" or "failed", trials, then mean metres per trial walked, of the oracle's and of
    each phase. Groups whose records carry no walk marks are left out."""
    groups: dict[tuple[str, ...], list[Record]] = {}
    for record in records:
        groups.setdefault((*key(record), "found" if record["success"] else "failed"), []).append(record)
    rows = []
    for group, mine in sorted(groups.items()):
        means = phase_means(mine)
        if means is None:
            continue
        n, split = means
        oracle = [r["oracle_m"] for r in mine if r.get("oracle_m") is not None]
        rows.append([*group, str(n), _f(sum(split), ".1f"), _f(float(np.mean(oracle)) if oracle else math.nan, ".1f"),
                     *[_f(v, ".1f") for v in split]])
    return rows


def worst_trials(records: list[Record], n: int = 10) -> list[Record]:
    """The ``n`` trials with the lowest SPL (unknown SPL first among failures), then the longest."""
    def badness(r: Record) -> tuple[float, float]:
        score = r.get("spl")
        distance = r.get("distance_m")
        return (-1.0 if score is None else score, -(distance if distance is not None else math.inf))
    return sorted(records, key=badness)[:n]


def trial_picture(record: Record, world: World, path: Path, oracle: np.ndarray | None = None) -> Path:
    """One trial's path over the floor plan, the goal's labels gold, the oracle's path dashed (if given)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 8))
    draw_floorplan(ax, world)
    draw_tags(ax, world, goal_tags=[t.id for t in world.label_tags(record["goal"])])
    if record.get("trajectory"):
        verdict = f"{record['distance_m']:.1f} m" if record["success"] else "failed"
        colour = "tab:green" if record["success"] else "tab:red"
        trajectory = np.array(record["trajectory"])
        draw_path(ax, trajectory, colour=colour,
                  label=f"{record.get('navigator', '')} seed {record['seed']}: {verdict}")
        draw_walk_marks(ax, trajectory, record["distance_m"], record, colour=colour)
    if oracle is not None:
        ax.plot(oracle[:, 0], oracle[:, 1], color="black", ls="--", lw=1.5, label="oracle")
    x0, x1, y0, y1 = world.floorplan.extent
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    spl = record.get("spl")
    why = f"\n{record['explanation']}" if record.get("explanation") else ""
    ax.set_title(f"{world.name}: {record['goal']} (SPL {_f(spl)}; {record.get('reason', '')}){why}", fontsize=9)
    ax.legend(loc="lower right", fontsize=7)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90)
    plt.close(fig)
    return path


def worst_pictures(worst: list[Record], worlds: dict[str, World], folder: Path) -> list[Path | None]:
    """A picture per worst trial in ``folder`` (None where its world is not known)."""
    from sim.experiments.study import slug
    from sim.world.oracle import oracle_paths

    out: list[Path | None] = []
    for i, record in enumerate(worst, 1):
        world = worlds.get(record.get("world", ""))
        if world is None:
            out.append(None)
            continue
        try:
            oracle = oracle_paths(world, [record["goal"]])[record["goal"]].path
        except ValueError:
            oracle = None
        name = f"{i:02d}-{slug(world.name, 60)}-{slug(record.get('navigator', ''), 20)}-{slug(record['goal'])}" \
               f"-{record['seed']}.png"
        out.append(trial_picture(record, world, folder / name, oracle))
    return out


def summary_markdown(records: list[Record], *, worst: list[Record], pictures: Iterable[Path | None],
                     relative_to: Path, habits: Sequence[str] = ()) -> str:
    """The sections over all trials: overall, by style and signage, failures, where the walking went, how the
    walks moved (``habits``: the table of :func:`sim.experiments.habits.habits_table`; none, no section), how
    much a walk depends on its seed, per world, the ten worst."""
    nav = lambda r: r.get("navigator", "paper")  # noqa: E731
    generated = any(r.get("style") for r in records)
    lines = ["## Over all trials", "",
             "Success: goal's label read. SPL: success x oracle / max(distance, oracle) (Anderson et al. 2018), "
             "mean over all trials. Ratio to oracle and distance: mean over successful trials. Wall: seconds per "
             "trial.", ""]
    lines += grouped_table(records, ["navigator"], lambda r: (nav(r),))
    if generated:
        lines += ["", "### By style", ""]
        lines += grouped_table(records, ["navigator", "style"], lambda r: (nav(r), r.get("style") or "-"))
        lines += ["", "### By signage level", ""]
        lines += grouped_table(records, ["navigator", "signage"], lambda r: (nav(r), r.get("signage") or "-"))
        lines += ["", "### By goal role", "",
                  "Why the generator chose each goal (world.json's `goal_roles`; `worlds/README.md`, *Goals*): "
                  "behind a loop, off a dead end, named by no arrow, off a hall, through a room, or far.", ""]
        lines += grouped_table(records, ["navigator", "role"], lambda r: (nav(r), r.get("role") or "-"))
    lines += ["", "### Failures by reason", ""]
    failures = Counter((nav(r), reason_kind(r), explanation_kind(r)) for r in records if not r["success"])
    if failures:
        lines += ["Explanation: why the goal's label went unread, by the perception's reading rules along the path "
                  "and what the robot knew (`sim/experiments/diagnosis.py`; particulars per trial in trials.csv):",
                  "", *[f"- *{kind}*: {meaning}" for kind, meaning in KINDS.items()], "",
                  "| navigator | reason | explanation | trials |", "| --- | --- | --- | --- |"]
        lines += [f"| {n} | {reason} | {kind} | {count} |" for (n, reason, kind), count in sorted(failures.items())]
    else:
        lines.append("None: every trial found its goal.")
    walks = walk_rows(records, lambda r: (nav(r), r.get("signage") or "-"))
    walk_header = ["navigator", "signage", *WALK_HEADER]
    if walks:
        lines += ["", "### Where the walking went", "",
                  "Mean metres per trial, split where the robot first came within 8 m (by the floor plan) of a pose "
                  "that reads the goal's label (*far* before it) and where it first saw the label, unread, by the "
                  "spotting rule (`sim/experiments/walk.py`). Metres in the later phases beyond the oracle's last "
                  "few are a search that came close and turned away.", "",
                  "| " + " | ".join(walk_header) + " |", "|" + " --- |" * len(walk_header),
                  *["| " + " | ".join(row) + " |" for row in walks]]
    if habits:
        lines += ["", "### How the walks moved", "", habits_legend(), "", *habits]
    spread = seed_spread(records)
    if spread:
        lines += ["", "### How much a walk depends on its seed", "",
                  "Over the goals run with two seeds or more, which differ only by the seed (the start's jitter, "
                  "the stuck recovery's turning direction and, in geometric mode, the detection noise): the "
                  "standard deviation of one goal's SPL across its seeds, the share of pairs "
                  f"of seeds whose SPL differ by more than {APART_SPL:g} and that score alike (within "
                  f"{ALIKE_SPL:g}), and the paired trials a change of {RESOLVE_SPL:g} SPL needs to stand at two "
                  "standard errors if it draws every walk afresh as a new seed does.", "",
                  "| navigator | goals | SPL sd across seeds | pairs apart | pairs alike | trials needed |",
                  "| --- | --- | --- | --- | --- | --- |"]
        lines += [f"| {nav} | {s.goals} | {s.sd:.3f} | {s.apart:.0%} | {s.alike:.0%} | {s.trials_needed} |"
                  for nav, s in spread.items()]
    lines += ["", "### Per world", ""]
    lines += grouped_table(records, ["world", "style", "signage", "navigator"],
                           lambda r: (r.get("world", ""), r.get("style") or "-", r.get("signage") or "-", nav(r)))
    lines += ["", f"### The {len(worst)} worst trials (lowest SPL)", "",
              "| # | world | navigator | goal | seed | result | distance (m) | oracle (m) | SPL | picture |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for i, (record, picture) in enumerate(zip(worst, pictures), 1):
        why = f"; {record['explanation']}" if record.get("explanation") else ""
        result = "found" if record["success"] else f"failed: {record.get('reason', '')}{why}"
        link = f"[path]({picture.relative_to(relative_to).as_posix()})" if picture is not None else "-"
        lines.append(f"| {i} | {record.get('world', '')} | {nav(record)} | {record['goal']} | {record['seed']} | "
                     f"{result} | {_f(record.get('distance_m'), '.1f')} | {_f(record.get('oracle_m'), '.1f')} | "
                     f"{_f(record.get('spl'))} | {link} |")
    return "\n".join(lines) + "\n"
