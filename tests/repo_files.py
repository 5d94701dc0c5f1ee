"""Load the repository's scripts and benchmarks (files run by path, not packages) as modules for tests."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parent.parent


def load_file(relative: str, name: str,
              register: Callable[[str, ModuleType], None] = sys.modules.__setitem__) -> ModuleType:
    """The module of the file ``relative`` to the repository's root, registered as ``name`` before it runs
    (dataclasses look their module up in ``sys.modules``; ``register``, e.g. a monkeypatch's ``setitem``, to
    have it taken out after the test)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / relative)
    module = importlib.util.module_from_spec(spec)
    register(name, module)
    spec.loader.exec_module(module)
    return module


def refused_in_one_line(main: Callable[[Sequence[str]], int], argv: Sequence[str], capsys: pytest.CaptureFixture,
                        prog: str) -> str:
    """What a script's ``main`` printed on refusing ``argv``, after checking it exited 2 with one line on stderr
    that starts with ``prog: ``."""
    with pytest.raises(SystemExit) as exited:
        main(argv)
    assert exited.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{prog}: ") and err.count("\n") == 1
    return err
