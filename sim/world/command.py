"""Generate buildings and check worlds.

  abstract-map world generate --seed N --out DIR [--style office|hospital|museum|campus|park]
                              [--size small|medium|large] [--signage complete|sparse|misleading]
                              [--arrows way|bearing]
  abstract-map world check DIR [--write-oracle]

`generate` writes a world folder (world.json with the oracle per goal,
floorplan.png, tags.json, hierarchy.xml); the same arguments give the same
bytes. `--arrows bearing` writes fingerposts (each arrow points at its place
as the crow flies) instead of wayfinding signs (each points the way to set
off: the default, `way`); the building is otherwise the same. It refuses a
non-empty DIR unless DIR holds exactly this generation.

`check` checks any world folder (or world name): tags on walls and readable
from reachable space, every room and goal reachable, every arrow within 45
degrees of its route's first leg (of its place's bearing, in a world generated
with `--arrows bearing`), every phrase true, the stored oracle current.
It prints a table of what fails and exits 1 when anything fails, 0 otherwise.
`--write-oracle` stores the computed oracle per goal in world.json.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from abstract_map.cli import ExitError

SUMMARY = "generate buildings (world generate) and check world folders (world check)"
EXTRA = "sim"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from sim.world.styles import SIGNAGE, SIZES, STYLES
    from sim.world.truth import ARROW_READINGS, DEFAULT_ARROWS

    sub = parser.add_subparsers(dest="action", metavar="ACTION")
    gen = sub.add_parser("generate", help="write a generated building as a world folder",
                         description="Write a generated building (same arguments, same bytes).")
    gen.add_argument("--seed", required=True, help="non-negative integer")
    gen.add_argument("--out", required=True, type=Path, help="folder to write (must not exist, or be empty)")
    gen.add_argument("--style", default="office", help=f"one of {', '.join(STYLES)} (default office)")
    gen.add_argument("--size", default="medium", help=f"one of {', '.join(SIZES)} (default medium)")
    gen.add_argument("--signage", default="complete", help=f"one of {', '.join(SIGNAGE)} (default complete)")
    gen.add_argument("--arrows", default=DEFAULT_ARROWS,
                     help=f"what arrows point along: one of {', '.join(ARROW_READINGS)} (default {DEFAULT_ARROWS}: "
                          "the way to set off; bearing: the place, as fingerposts do)")
    chk = sub.add_parser("check", help="check a world folder; exit 1 when anything fails",
                         description="Check a world against its floor plan; exit 1 when anything fails.")
    chk.add_argument("world", help="world folder or name")
    chk.add_argument("--write-oracle", action="store_true", help="store the computed oracle per goal in world.json")


def run(args: argparse.Namespace) -> int:
    if args.action == "generate":
        return _generate(args)
    if args.action == "check":
        return _check(args)
    raise ExitError("say what to do: world generate ... or world check DIR (see abstract-map world --help)")


def _generate(args: argparse.Namespace) -> int:
    from sim.world.generator import generate, write_world

    try:
        seed = int(args.seed)
    except ValueError:
        raise ExitError(f"--seed must be a non-negative integer, got {args.seed!r}") from None
    t0 = time.perf_counter()
    try:
        generated = generate(seed, style=args.style, size=args.size, signage=args.signage, arrows=args.arrows)
        folder = write_world(generated, args.out)
    except (ValueError, FileExistsError) as exc:
        raise ExitError(str(exc)) from None
    world = generated.world
    labels = sum(t.kind == "label" for t in world.tags.values())
    print(f"{folder}: {generated.name}, {len(generated.layout.rooms)} rooms, {len(world.tags)} tags "
          f"({labels} labels, {len(world.tags) - labels} signs), goals {', '.join(sorted(world.goals))} "
          f"in {time.perf_counter() - t0:.1f} s")
    return 0


def _check(args: argparse.Namespace) -> int:
    from sim.world.check import check_world, write_oracle
    from sim.world.data import WorldError, load_world, resolve_world

    try:
        folder = resolve_world(args.world)
        world = load_world(folder)
    except WorldError as exc:
        raise ExitError(str(exc)) from None
    report = check_world(world)
    if args.write_oracle and report.oracle_m:
        write_oracle(folder, report.oracle_m)
        report.findings = [f for f in report.findings if f.kind != "oracle"]  # now current
    print(report.table())
    if args.write_oracle and report.oracle_m:
        print(f"wrote oracle_m for {len(report.oracle_m)} goal(s) to {folder / 'world.json'}")
    return 0 if report.ok else 1
