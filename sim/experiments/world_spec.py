"""World specs for ``--world``: a world by name, a world folder, or a range of generated buildings.

Forms (``--world`` may be given several times; a study runs over all of them):

- ``zoo``: a world under ``worlds/`` by name; ``path/to/folder``: a world folder.
- ``generated:1000-1049``: generated buildings, seeds 1000 to 1049 inclusive
  (``generated:7`` is one seed). Size is medium unless given. Style and signage
  level cycle with the seed over the generator's registries, style fastest:
  seed ``s`` is style ``SEED_CYCLE[s % 4]`` (office, hospital, museum, campus)
  and signage ``SIGNAGE[(s // 4) % 3]``, so any 12 consecutive seeds cover
  every cycled style and signage level together. A style outside the cycle
  (``park``) is built only when named.
  Fixing one of them (``style=...`` or ``signage=...``) cycles only the other
  (by ``s % len``).
- ``generated:1000-1009:style=hospital,signage=sparse,size=small``: fixed
  settings, any subset of ``style``, ``size`` and ``signage``.
- ``generated:0-19:style=park,arrows=bearing``: the same buildings with
  fingerposts, arrows pointing at their places as the crow flies, instead of
  the way to set off (``arrows=way``, the default; ``sim.world.truth``).

Seeds 0-999 are for development (tuning), 1000-1999 only for reporting:
:func:`seed_split` names the split of a seed. Generated worlds are written
once under a root folder (a study's ``OUT/worlds/``) and re-used.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from sim.world.data import WorldError, resolve_world

GENERATED = "generated:"
DEV_SEEDS = range(0, 1000)  # tune on these
TEST_SEEDS = range(1000, 2000)  # report on these; tune nothing on them
MAX_WORLDS = 10_000  # a cap on one spec's seed range, so a typo cannot ask for a million buildings
_RANGE = re.compile(r"^(\d+)(?:-(\d+))?$")


class WorldSpecError(ValueError):
    """A ``--world`` spec that cannot be understood."""


@dataclass(frozen=True)
class GeneratedSpec:
    """One generated building: what :func:`sim.world.generator.generated_world` is called with."""

    seed: int
    style: str
    size: str
    signage: str
    arrows: str = "way"  # what the signs' arrows point along (``sim.world.truth.ARROW_READINGS``)


@dataclass(frozen=True)
class WorldSpec:
    """One ``--world`` argument, parsed."""

    text: str  # as given
    path: str | None = None  # a world name or folder (None for generated worlds)
    seeds: tuple[int, int] | None = None  # first and last seed, inclusive (generated worlds)
    style: str | None = None  # None: cycles with the seed
    size: str = "medium"
    signage: str | None = None  # None: cycles with the seed
    arrows: str = "way"  # the route's first leg (wayfinding signs) or ``bearing`` (fingerposts)

    def generated(self) -> list[GeneratedSpec]:
        """The buildings of a ``generated:`` spec, in seed order (empty for a named world)."""
        if self.seeds is None:
            return []
        from sim.world.styles import SEED_CYCLE, SIGNAGE

        styles, levels = list(SEED_CYCLE), list(SIGNAGE)
        out = []
        for seed in range(self.seeds[0], self.seeds[1] + 1):
            style = self.style or styles[seed % len(styles)]
            if self.signage:
                level = self.signage
            elif self.style:
                level = levels[seed % len(levels)]
            else:
                level = levels[(seed // len(styles)) % len(levels)]
            out.append(GeneratedSpec(seed, style, self.size, level, self.arrows))
        return out


def parse_world_spec(text: str) -> WorldSpec:
    """Parse one ``--world`` argument; a :class:`WorldSpecError` says what was expected."""
    if not text.startswith(GENERATED):
        if not text.strip():
            raise WorldSpecError("--world: empty; expected a world name, a folder or generated:A-B")
        return WorldSpec(text=text, path=text)
    from sim.world.styles import SIGNAGE, SIZES, STYLES
    from sim.world.truth import ARROW_READINGS

    example = "e.g. generated:1000-1049 or generated:1000-1009:style=hospital,signage=sparse"
    body = text[len(GENERATED):]
    seeds_text, _, options_text = body.partition(":")
    match = _RANGE.match(seeds_text)
    if not match:
        raise WorldSpecError(f"--world {text!r}: expected seeds A-B after 'generated:', {example}")
    first = int(match.group(1))
    last = int(match.group(2)) if match.group(2) is not None else first
    if last < first:
        raise WorldSpecError(f"--world {text!r}: seeds run from low to high, {example}")
    if last - first + 1 > MAX_WORLDS:
        raise WorldSpecError(f"--world {text!r}: {last - first + 1} worlds; at most {MAX_WORLDS} per spec")
    tables = {"style": STYLES, "size": SIZES, "signage": SIGNAGE, "arrows": ARROW_READINGS}
    options: dict[str, str] = {}
    for item in filter(None, options_text.split(",")):
        key, eq, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not eq or key not in tables:
            raise WorldSpecError(f"--world {text!r}: option {item!r}; expected key=value with key one of "
                                 f"{sorted(tables)}, {example}")
        if value not in tables[key]:
            raise WorldSpecError(f"--world {text!r}: {key} {value!r}; known: {', '.join(tables[key])}")
        if key in options:
            raise WorldSpecError(f"--world {text!r}: {key} given twice")
        options[key] = value
    return WorldSpec(text=text, seeds=(first, last), style=options.get("style"), size=options.get("size", "medium"),
                     signage=options.get("signage"), arrows=options.get("arrows", "way"))


def seed_split(seed: int) -> str:
    """"dev" for seeds 0-999 (tuning), "test" for 1000-1999 (reporting only), else "other"."""
    return "dev" if seed in DEV_SEEDS else "test" if seed in TEST_SEEDS else "other"


def generated_folder(spec: GeneratedSpec, root: Path) -> Path:
    """Where ``spec``'s building lives under ``root`` (written there if absent)."""
    from sim.world.generator import generated_world

    return generated_world(spec.seed, style=spec.style, size=spec.size, signage=spec.signage, arrows=spec.arrows,
                           root=root)


def resolve_worlds(specs: Iterable[WorldSpec], root: Path, *,
                   build: Callable[[list[GeneratedSpec], Path], list[Path]] | None = None) -> list[Path]:
    """The world folders of ``specs`` in order, duplicates dropped; generated ones built under ``root``.

    ``build(generated, root)`` writes the generated buildings (default: one after another); a named
    world that is missing raises :class:`sim.world.data.WorldError`.
    """
    folders: list[Path] = []
    for spec in specs:
        if spec.path is not None:
            folders.append(resolve_world(spec.path))
            continue
        todo = spec.generated()
        folders += (build or _build_serially)(todo, root)
    unique = list(dict.fromkeys(folder.resolve() for folder in folders))
    return unique


def _build_serially(todo: list[GeneratedSpec], root: Path) -> list[Path]:
    return [generated_folder(g, root) for g in todo]


__all__ = ["WorldSpec", "GeneratedSpec", "WorldSpecError", "WorldError", "parse_world_spec", "resolve_worlds",
           "seed_split", "generated_folder", "DEV_SEEDS", "TEST_SEEDS"]
