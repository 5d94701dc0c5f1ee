"""The ``abstract-map`` command.

Subcommands are plugins: each is a module named in the ``abstract_map.commands``
entry-point group (``pyproject.toml``), with a docstring (its ``--help``), a
one-line ``SUMMARY``, optionally the ``EXTRA`` it needs, ``add_arguments(parser)``
and ``run(args) -> int``. The core contributes ``imagine``; the simulator
contributes its own commands the same way, so the core never names it.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from importlib.metadata import entry_points
from types import ModuleType

GROUP = "abstract_map.commands"


class ExitError(Exception):
    """An error for the user: printed as one line, exit code 2."""


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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
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
    except ExitError as exc:
        print(f"abstract-map {args.command}: {exc}", file=sys.stderr)
        return 2
    except ModuleNotFoundError as exc:
        if not _is_missing_dependency(exc, args.module):
            raise
        print(_missing_message(args.command, args.extra, exc), file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
