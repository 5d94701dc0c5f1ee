"""The ``abstract-map`` command.

Subcommands are a registry: each names the module that defines it (an
``add_arguments(parser)`` and a ``run(args) -> int``). The simulator's
subcommands live in ``sim`` and are imported only when that package and its
extra are installed, so the core works without them.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType

from .errors import AbstractMapError, one_line

SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "imagine": ("abstract_map.imagine_command", "replay a scenario of cues and write the imagined map after each"),
    "trial": ("sim.trial_command", "run one closed-loop trial in a pybullet world (needs the [sim] extra)"),
    "study": ("sim.study_command", "run every goal of a world N times and compare with the paper (needs [sim])"),
}


class ExitError(AbstractMapError):
    """An error for the user: printed as one line, exit code 2."""


def _writable_folder(flag: str, folder: Path) -> None:
    """``folder`` exists as a writable folder, or can be created (its nearest existing ancestor is one)."""
    probe = folder
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        raise ExitError(f"{flag} {str(folder)!r}: {str(probe)!r} is a file, not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise ExitError(f"{flag} {str(folder)!r}: cannot write in {str(probe)!r}")


def output_file(flag: str, path: Path, *, suffixes: Sequence[str] | None = None) -> Path:
    """Check an output file argument before any work starts: ExitError (exit 2) naming the flag."""
    if str(path).strip() == "" or path.name in ("", ".", ".."):
        raise ExitError(f"{flag}: expected a file name, got {str(path)!r}")
    if path.is_dir():
        raise ExitError(f"{flag} {str(path)!r}: is a folder, expected a file")
    if suffixes is not None and path.suffix.lower().lstrip(".") not in suffixes:
        raise ExitError(f"{flag} {str(path)!r}: expected one of the suffixes {sorted('.' + s for s in suffixes)}")
    _writable_folder(flag, path.parent)
    return path


def output_folder(flag: str, path: Path) -> Path:
    """Check an output folder argument before any work starts: ExitError (exit 2) naming the flag."""
    if str(path).strip() == "":
        raise ExitError(f"{flag}: expected a folder, got ''")
    if path.exists() and not path.is_dir():
        raise ExitError(f"{flag} {str(path)!r}: is a file, expected a folder")
    _writable_folder(flag, path)
    return path


def distinct_outputs(**paths: Path | None) -> None:
    """Two output arguments may not name the same file."""
    seen: dict[Path, str] = {}
    for flag, path in paths.items():
        if path is None:
            continue
        key = path.resolve()
        if key in seen:
            raise ExitError(f"{flag} and {seen[key]} name the same file {str(path)!r}")
        seen[key] = flag


def _module(name: str) -> ModuleType | None:
    try:
        return importlib.import_module(SUBCOMMANDS[name][0])
    except ModuleNotFoundError as exc:
        if exc.name and (exc.name.startswith(("abstract_map", "sim")) and exc.name != SUBCOMMANDS[name][0]):
            raise
        return None


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="abstract-map",
        description="Navigate unseen buildings from human signs and labels (Talbot et al. 2020).",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (_, summary) in SUBCOMMANDS.items():
        module = _module(name)
        sub = subparsers.add_parser(name, help=summary, description=(module.__doc__ if module else summary),
                                    formatter_class=argparse.RawDescriptionHelpFormatter)
        if module is None:
            sub.set_defaults(missing=name)
        else:
            module.add_arguments(sub)
            sub.set_defaults(run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    if getattr(args, "missing", None):
        print(f"abstract-map {args.missing}: the simulator is not installed; "
              'install it with: pip install "abstract-map[sim]"', file=sys.stderr)
        return 2
    try:
        return int(args.run(args))
    except AbstractMapError as exc:
        print(one_line(f"abstract-map {args.command}: {exc}"), file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
