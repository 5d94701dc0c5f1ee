"""The command line: subcommands come from the entry-point group, missing extras get one line and exit 2."""

from __future__ import annotations

import sys
import types
from importlib.metadata import EntryPoint

import pytest

from abstract_map import cli


def test_every_package_contributes_its_subcommands():
    found = cli.commands()
    assert {"imagine", "trial", "study", "compare"} <= set(found)
    assert all(isinstance(m, types.ModuleType) for m in found.values())


def test_a_command_whose_dependency_is_missing_says_which_extra(monkeypatch, capsys):
    module = types.ModuleType("fake_command")
    module.__doc__ = "A command that needs a package that is not installed."
    module.SUMMARY = "needs a missing package"
    module.EXTRA = "sim"
    module.add_arguments = lambda parser: None

    def run(args):
        raise ModuleNotFoundError("No module named 'not_installed_pkg'", name="not_installed_pkg")

    module.run = run
    monkeypatch.setitem(sys.modules, "fake_command", module)
    point = EntryPoint(name="fake", value="fake_command", group=cli.GROUP)
    monkeypatch.setattr(cli, "entry_points", lambda group: [point])
    assert cli.main(["fake"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["abstract-map fake: needs the package 'not_installed_pkg', which is not installed; "
                   'install it with: pip install "abstract-map[sim]"']


def test_a_bug_in_our_own_module_is_not_hidden(monkeypatch):
    point = EntryPoint(name="broken", value="abstract_map.no_such_module", group=cli.GROUP)
    monkeypatch.setattr(cli, "entry_points", lambda group: [point])
    with pytest.raises(ModuleNotFoundError):
        cli.commands()
