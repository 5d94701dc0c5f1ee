"""Which factor of the guided navigator's goal belief leads towards the goal, and which away: an evidence audit.

Usage: ``python scripts/evidence_audit.py --world generated:24-43 [--seed 0] [--goals 5] [--out FILE.jsonl]
[--variant "arrows: unseen_detour=1.0"] ...`` (development seeds only: the audit knows where each goal hangs).

Runs one guided trial (geometric, as a study runs it) per goal and prints, per factor and per variant (a factor
made again with other ``RouteParams`` fields, ``"FACTOR: FIELD=VALUE, ..."``, or the whole belief with other
``BeliefParams`` fields, ``"belief: tail_weight=0.1"``), the mean over trials of its time-averaged gain (nats;
``sim.experiments.evidence_audit``), the standard error and how many trials it led astray by more than half a
nat, by signage level. ``--out`` appends one JSON line per trial (resumable).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
from tqdm import tqdm

from abstract_map.errors import AbstractMapError
from sim.experiments.evidence_audit import TARGETS, AuditRecord, Variant, audit_trial
from sim.experiments.world_spec import parse_world_spec, resolve_worlds, seed_split
from sim.world.data import load_world


def parse_variant(text: str) -> Variant:
    """``"FACTOR: FIELD=VALUE, ..."`` as a :class:`Variant` (FACTOR ``belief`` for the whole belief, with
    ``BeliefParams`` fields); a ValueError says what was expected."""
    factor, colon, rest = text.partition(":")
    if not colon:
        raise ValueError(f"--variant {text!r}: expected 'FACTOR: FIELD=VALUE, ...' with FACTOR one of "
                         f"{list(TARGETS)}")
    changes = {}
    for item in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not eq or not math.isfinite(number):
            raise ValueError(f"--variant {text!r}: {item!r}; expected FIELD=NUMBER")
        changes[key.strip()] = number
    try:
        return Variant(factor.strip(), changes)
    except ValueError as exc:
        raise ValueError(f"--variant {text!r}: {exc}") from None


def read_records(path: Path | None) -> dict[tuple[str, str, int], AuditRecord]:
    """The trials already audited in ``path`` (one JSON line each), by (world, goal, seed); a ValueError names
    the line that is not one."""
    done: dict[tuple[str, str, int], AuditRecord] = {}
    if path is None or not path.is_file():
        return done
    for number, line in enumerate(path.read_text().splitlines(), 1):
        try:
            record = AuditRecord(**json.loads(line))
        except (ValueError, TypeError) as exc:
            raise ValueError(f"--out {path}: line {number} is not an audited trial ({exc})") from None
        done[(record.world, record.goal, record.seed)] = record
    return done


def summary(records: list[AuditRecord], signage: dict[str, str]) -> None:
    """Print each factor's mean gain over trials, overall and by signage level."""
    groups: dict[str, list[AuditRecord]] = defaultdict(list)
    for r in records:
        groups["all"].append(r)
        groups[signage.get(r.world, "?")].append(r)
    for group, rs in groups.items():
        found = sum(r.success for r in rs)
        print(f"{group}: {len(rs)} trials, {found} found")
        per: dict[str, list[float]] = defaultdict(list)
        for r in rs:
            for name, value in r.mean_gains().items():
                per[name].append(value)
        for name, values in sorted(per.items()):
            v = np.asarray(values)
            se = v.std(ddof=1) / math.sqrt(len(v)) if len(v) > 1 else math.nan
            print(f"  {name:40s} gain {v.mean():+.3f} ± {se:.3f} nats over {len(v):3d} trials; "
                  f"astray (< -0.5) in {int(np.sum(v < -0.5))}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--world", action="append", required=True, help="a world spec, e.g. generated:24-43")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--goals", type=int, default=5, help="goals per world (the study's order)")
    ap.add_argument("--variant", action="append", default=[],
                    help='e.g. "arrows: unseen_detour=1.0" or "belief: tail_weight=0.1"')
    ap.add_argument("--out", type=Path, help="append one JSON line per trial here; trials already in it are kept")
    ap.add_argument("--root", type=Path, default=Path("runs/audit-worlds"), help="where generated worlds are written")
    args = ap.parse_args(argv)
    try:
        variants = tuple(parse_variant(v) for v in args.variant)
        specs = [parse_world_spec(w) for w in args.world]
        tested = [g.seed for spec in specs if spec.path is None for g in spec.generated()
                  if seed_split(g.seed) == "test"]
        if tested:
            raise ValueError(f"--world: seeds {tested[:3]}... are test seeds (reporting only); audit development seeds")
        worlds = [load_world(folder) for folder in resolve_worlds(specs, args.root)]
        done = read_records(args.out)
    except (ValueError, AbstractMapError) as exc:
        print(f"evidence_audit: {exc}", file=sys.stderr)
        return 2
    jobs = [(str(world.root), goal) for world in worlds for goal in list(world.goals)[:args.goals]]
    records = []
    for folder, goal in tqdm(jobs, desc="audit", unit="trial", file=sys.stderr):
        key = (folder, goal, args.seed)
        if key not in done:
            done[key] = audit_trial(folder, goal, seed=args.seed, variants=variants)
            if args.out is not None:
                with args.out.open("a") as fh:
                    fh.write(json.dumps(done[key].__dict__) + "\n")
        records.append(done[key])
    signage = {str(world.root): str((world.generator or {}).get("signage", "hand-made")) for world in worlds}
    summary(records, signage)
    return 0


if __name__ == "__main__":
    sys.exit(main())
