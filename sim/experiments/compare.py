"""Two studies trial by trial: did a change (of code, navigator or parameter) help, by more than the spread?

A study's trials differ by building, goal and seed, and a single trial's SPL
moves by 0.1 or more when a navigator changes at all, so two studies' mean SPLs
say little unless the same trials are compared. :func:`compare` pairs the
trials two study folders share (same world, goal, seed and perception; same
navigator too, unless two are named) and gives, per group (all, then each
signage level, style, ...):

- the trials found by each side;
- the mean SPL of each and the mean change per trial with its standard error
  (the sample standard deviation of the changes over the square root of their
  number): a change under two standard errors is within the spread;
- the geometric mean ratio of the walks found by both (new over base), and how
  many paired walks went the same way (found alike, within ``SAME_WALK_M``): a
  change of code that moves few walks is resolved by fewer trials than one
  that moves them all;
- where the found walks went (:data:`sim.experiments.walk.PHASES`, mean metres
  per found trial), when the records carry the walk's marks.

Trials found in one folder only are counted and named in the report, never
silently left out.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sim.experiments.walk import PHASES, phase_means
from sim.world.data import World, load_world

Record = dict[str, Any]
Key = tuple[Any, ...]
PAIR_FIELDS = ("world", "goal", "seed", "perception")  # what makes two trials the same trial
GROUPS = ("signage", "style")  # the default groups after "all"
SAME_WALK_M = 0.01  # m; two paired walks this close in length, found alike, went the same way


class CompareError(ValueError):
    """A study folder that cannot be compared: missing, empty or holding unreadable records."""


@dataclass(frozen=True)
class Row:
    """One group's comparison; SPL in [0, 1], walks in metres."""

    group: str  # "all" or "FIELD=value"
    trials: int  # paired trials
    found_base: int
    found_new: int
    spl_base: float
    spl_new: float
    change: float  # mean SPL change per trial, new - base
    change_se: float  # its standard error (nan for one trial)
    walk_ratio: float | None  # geometric mean of new / base walks found by both (None: none found by both)
    same: int  # paired walks that went the same way: found alike, lengths within SAME_WALK_M
    phases_base: tuple[float, ...] | None  # mean m per found trial, by PHASES (None: no marks)
    phases_new: tuple[float, ...] | None


@dataclass(frozen=True)
class Comparison:
    rows: list[Row]
    only_base: list[Key]  # trials in the base folder alone
    only_new: list[Key]


def load_records(folder: Path, navigator: str | None = None) -> list[Record]:
    """Every trial record of the study ``folder`` (``DIR/trials/*/*.json``), of ``navigator`` only if given.
    :class:`CompareError` when the folder holds no trials or a record is unreadable (named)."""
    folder = Path(folder)
    files = sorted((folder / "trials").glob("*/*.json"))
    if not files:
        raise CompareError(f"{folder}: no trial records (expected a study folder with trials/WORLD/*.json)")
    records = []
    for path in files:
        try:
            record = json.loads(path.read_text())
        except (OSError, ValueError) as exc:
            raise CompareError(f"{path}: not a readable trial record ({exc})") from exc
        missing = [f for f in (*PAIR_FIELDS, "navigator", "success", "spl", "distance_m")
                   if not isinstance(record, dict) or f not in record]
        if missing:
            raise CompareError(f"{path}: not a trial record (missing {', '.join(missing)})")
        if navigator is None or record["navigator"] == navigator:
            records.append(record)
    if not records:
        raise CompareError(f"{folder}: no trials of navigator {navigator!r}")
    return records


def study_world(folders: Sequence[Path], name: str) -> World:
    """The world ``name`` that study ``folders`` ran: the first one's own ``worlds/NAME`` (its generated
    buildings), else a named world (:func:`sim.world.data.load_world`, e.g. ``zoo``); its
    :class:`~sim.world.data.WorldError` when neither is there."""
    for folder in folders:
        own = Path(folder) / "worlds" / name
        if own.is_dir():
            return load_world(own)
    return load_world(name)


def pair_key(record: Record, with_navigator: bool) -> Key:
    return tuple(record[f] for f in PAIR_FIELDS) + ((record["navigator"],) if with_navigator else ())


def compare(base: Sequence[Record], new: Sequence[Record], *, groups: Sequence[str] = GROUPS,
            with_navigator: bool = True) -> Comparison:
    """Pair ``base`` and ``new`` trial by trial (:data:`PAIR_FIELDS`, and the navigator if ``with_navigator``)
    and compare every group: all, then each value of each field in ``groups`` (taken from the base record, or
    the new one where the base has none: a study run before the field was recorded).
    :class:`CompareError` when a side repeats a trial or no trial is shared."""
    by_base, by_new = _index(base, with_navigator, "base"), _index(new, with_navigator, "new")
    shared = sorted(set(by_base) & set(by_new), key=repr)
    if not shared:
        raise CompareError("the two studies share no trial (same world, goal, seed and perception)")
    pairs = [(by_base[k], by_new[k]) for k in shared]
    rows = [_row("all", pairs)]
    for field in groups:
        values = sorted({_group_value(p, field) for p in pairs})
        rows += [_row(f"{field}={v}", [p for p in pairs if _group_value(p, field) == v]) for v in values]
    return Comparison(rows, sorted(set(by_base) - set(by_new), key=repr), sorted(set(by_new) - set(by_base), key=repr))


def _group_value(pair: tuple[Record, Record], field: str) -> str:
    """The pair's value of ``field``: the base record's, else the new one's; "-" when neither has one (None and
    "" count as none)."""
    base, new = pair
    value = base.get(field)
    if value in (None, ""):
        value = new.get(field)
    return "-" if value in (None, "") else str(value)


def _index(records: Sequence[Record], with_navigator: bool, side: str) -> dict[Key, Record]:
    out: dict[Key, Record] = {}
    for r in records:
        key = pair_key(r, with_navigator)
        if key in out:
            raise CompareError(f"the {side} study has the trial {key} twice")
        out[key] = r
    return out


def _row(group: str, pairs: list[tuple[Record, Record]]) -> Row:
    spl_b = np.array([float(b["spl"]) for b, _ in pairs])
    spl_n = np.array([float(n["spl"]) for _, n in pairs])
    diff = spl_n - spl_b
    se = float(diff.std(ddof=1) / math.sqrt(len(diff))) if len(diff) > 1 else math.nan
    both = [(float(b["distance_m"]), float(n["distance_m"])) for b, n in pairs
            if b["success"] and n["success"] and float(b["distance_m"]) > 0 and float(n["distance_m"]) > 0]
    ratio = float(np.exp(np.mean([math.log(n / b) for b, n in both]))) if both else None
    same = sum(bool(b["success"]) == bool(n["success"])
               and abs(float(b["distance_m"]) - float(n["distance_m"])) <= SAME_WALK_M for b, n in pairs)
    return Row(group, len(pairs), sum(bool(b["success"]) for b, _ in pairs), sum(bool(n["success"]) for _, n in pairs),
               float(spl_b.mean()), float(spl_n.mean()), float(diff.mean()), se, ratio, same,
               _phase_means([b for b, _ in pairs]), _phase_means([n for _, n in pairs]))


def _phase_means(records: list[Record]) -> tuple[float, ...] | None:
    """Mean metres per found trial in each of PHASES, over the found records that carry the walk's marks."""
    means = phase_means(r for r in records if r["success"])
    return None if means is None else tuple(means[1])


def markdown(result: Comparison, base_name: str, new_name: str) -> str:
    """The comparison as a Markdown report: a table of the groups, then the walks' phases, then the trials
    left unpaired."""
    lines = [f"# {new_name} against {base_name}, trial by trial", "",
             "| group | trials | found, base | found, new | SPL, base | SPL, new | change of SPL "
             "| walks found by both | walks the same |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in result.rows:
        se = "" if math.isnan(r.change_se) else f" ± {r.change_se:.3f}"
        walks = "" if r.walk_ratio is None else f"x {r.walk_ratio:.3f}"
        lines.append(f"| {r.group} | {r.trials} | {r.found_base} | {r.found_new} | {r.spl_base:.3f} | "
                     f"{r.spl_new:.3f} | {r.change:+.3f}{se} | {walks} | {r.same} |")
    lines += ["", "Change of SPL: mean per trial, new - base, with its standard error; walks found by both: the "
              f"geometric mean ratio new / base; walks the same: found alike and within {SAME_WALK_M:g} m in length "
              "(the walks the change did not move)."]
    top = result.rows[0]
    if top.phases_base is not None and top.phases_new is not None:
        lines += ["", "Where the found walks went (mean m per found trial):", "",
                  "| side | " + " | ".join(PHASES) + " |", "|---|" + "---|" * len(PHASES)]
        for name, split in (("base", top.phases_base), ("new", top.phases_new)):
            lines.append(f"| {name} | " + " | ".join(f"{v:.1f}" for v in split) + " |")
    for name, keys in (("base", result.only_base), ("new", result.only_new)):
        if keys:
            shown = "; ".join(" ".join(str(x) for x in k) for k in keys[:5])
            more = f" and {len(keys) - 5} more" if len(keys) > 5 else ""
            noun = "trial" if len(keys) == 1 else "trials"
            lines += ["", f"{len(keys)} {noun} only in the {name} study, not compared: {shown}{more}."]
    return "\n".join(lines) + "\n"
