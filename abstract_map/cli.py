"""The ``abstract-map`` command.

Subcommands are plugins: each is a module named in the ``abstract_map.commands``
entry-point group (``pyproject.toml``), with a docstring (its ``--help``), a
one-line ``SUMMARY``, optionally the ``EXTRA`` it needs, ``add_arguments(parser)``
and ``run(args) -> int``. The core contributes ``imagine``; the simulator
contributes its own commands the same way, so the core never names it.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from importlib.metadata import entry_points
from pathlib import Path
from types import ModuleType
from typing import NoReturn

from .errors import AbstractMapError, one_line

GROUP = "abstract_map.commands"


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


def _is_missing_dependency(exc: ModuleNotFoundError, module_name: str) -> bool:
    """Whether ``exc`` is another distribution's package that is not installed, not a bug in ``module_name``'s own."""
    own = {__name__.split(".")[0], module_name.split(".")[0]}
    return bool(exc.name) and exc.name.split(".")[0] not in own


def commands() -> dict[str, ModuleType | ModuleNotFoundError]:
    """Every registered subcommand by name: its module, or the missing dependency that stops it loading."""
    found: dict[str, ModuleType | ModuleNotFoundError] = {}
    for point in sorted(entry_points(group=GROUP), key=lambda p: p.name):
        try:
            found[point.name] = point.load()
        except ModuleNotFoundError as exc:
            if not _is_missing_dependency(exc, point.module):
                raise
            found[point.name] = exc
    return found


def _missing_message(name: str, extra: str | None, exc: ModuleNotFoundError) -> str:
    hint = f'; install it with: pip install "abstract-map[{extra}]"' if extra else ""
    return f"abstract-map {name}: needs the package {exc.name!r}, which is not installed{hint}"


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block), exit code 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, one_line(f"{self.prog}: {message}") + "\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="abstract-map",
        description="Navigate unseen buildings from human signs and labels (Talbot et al. 2020).",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, module in commands().items():
        if isinstance(module, ModuleNotFoundError):
            sub = subparsers.add_parser(name, help=f"(unavailable: {module.name} is not installed)")
            sub.set_defaults(missing=module)
            continue
        sub = subparsers.add_parser(name, help=module.SUMMARY, description=module.__doc__,
                                    formatter_class=argparse.RawDescriptionHelpFormatter)
        module.add_arguments(sub)
        sub.set_defaults(run=module.run, extra=getattr(module, "EXTRA", None), module=module.__name__)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    if getattr(args, "missing", None) is not None:
        print(_missing_message(args.command, None, args.missing), file=sys.stderr)
        return 2
    try:
        return int(args.run(args))
    except AbstractMapError as exc:
        print(one_line(f"abstract-map {args.command}: {exc}"), file=sys.stderr)
        return 2
    except ModuleNotFoundError as exc:
        if not _is_missing_dependency(exc, args.module):
            raise
        print(_missing_message(args.command, args.extra, exc), file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
