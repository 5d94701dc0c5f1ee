"""The command line the measurement scripts share: development seeds ``FIRST LAST``, or one world (``--world``).

``scripts/area_arrows.py``, ``scripts/arrow_spread.py`` and ``scripts/placement_by_cue.py`` each measure a
world, or the generator's buildings over a range of development seeds. This is their one way to be asked which.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from typing import TypeVar

from tqdm import tqdm

from abstract_map.errors import AbstractMapError
from sim.experiments.world_spec import GeneratedSpec, parse_world_spec
from sim.world.data import World, load_world

T = TypeVar("T")


def survey_parser(doc: str, seeds: tuple[int, int]) -> argparse.ArgumentParser:
    """A parser with the seeds (default ``seeds``) and ``--world``, described by ``doc``'s first paragraph."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("seeds", nargs="*", type=int,
                        help=f"first and last development seed (default {seeds[0]} {seeds[1]})")
    parser.add_argument("--world", help="a world folder or a name under worlds/ instead of generated seeds")
    parser.set_defaults(default_seeds=seeds)
    return parser


def on_world(parser: argparse.ArgumentParser, args: argparse.Namespace, name: str,
             measure: Callable[[World], T]) -> T:
    """``measure`` of ``--world``; a world that cannot be loaded or measured is one line naming it and exit 2."""
    try:
        return measure(load_world(args.world))
    except AbstractMapError as error:
        parser.exit(2, f"{name}: {error}\n")


def seed_range(parser: argparse.ArgumentParser, args: argparse.Namespace) -> tuple[int, int]:
    """The first and last development seed asked for (the parser's default without any); two seeds or none,
    else a usage error."""
    if len(args.seeds) not in (0, 2):
        parser.error("give FIRST LAST, or no seeds")
    first, last = args.seeds if args.seeds else args.default_seeds
    return first, last


def buildings(parser: argparse.ArgumentParser, args: argparse.Namespace,
              spec_tail: str = "") -> Sequence[GeneratedSpec]:
    """The development buildings ``generated:FIRST-LAST`` (``spec_tail``, e.g. ``":signage=complete"``, added),
    with a progress bar; two seeds or none, else a usage error."""
    first, last = seed_range(parser, args)
    return tqdm(parse_world_spec(f"generated:{first}-{last}{spec_tail}").generated(), desc="buildings")
