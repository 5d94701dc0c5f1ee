"""Atomic writes and safe file names (abstract_map/files.py)."""

from __future__ import annotations

import errno
import pathlib

import pytest
from hypothesis import given
from hypothesis import strategies as st

from abstract_map.files import atomic_path, safe_name, write_text_atomic


def test_a_failed_write_leaves_the_earlier_file_and_no_temporary(tmp_path):
    target = tmp_path / "r.json"
    target.write_text("earlier")
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("disk full")
    assert target.read_text() == "earlier"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json"]


def test_a_write_replaces_the_file_keeping_its_suffix_and_mode(tmp_path):
    target = tmp_path / "sub" / "picture.png"
    with atomic_path(target) as tmp:
        assert tmp.suffix == ".png" and tmp.parent == target.parent
        tmp.write_bytes(b"png")
    assert target.read_bytes() == b"png"
    assert target.stat().st_mode & 0o777 == 0o644
    write_text_atomic(target, "again")
    assert target.read_text() == "again"


def half_writes(monkeypatch):
    """Every Path write puts down half its data, then fails as a full disk would."""
    def write_text(self, data, *args, **kwargs):
        with open(self, "w") as handle:
            handle.write(data[: len(data) // 2])
        raise OSError(errno.ENOSPC, "No space left on device")

    def write_bytes(self, data):
        with open(self, "wb") as handle:
            handle.write(data[: len(data) // 2])
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pathlib.Path, "write_text", write_text)
    monkeypatch.setattr(pathlib.Path, "write_bytes", write_bytes)


def test_issue9_item1_save_on_a_full_disk_keeps_the_earlier_model(tmp_path, monkeypatch):
    from abstract_map import persistence

    from .helpers import make_map

    model = make_map()
    model.settle()
    path = tmp_path / "model.json"
    persistence.save(model, path)
    good = path.read_text()
    half_writes(monkeypatch)
    with pytest.raises(OSError):
        persistence.save(model, path)
    monkeypatch.undo()
    assert path.read_text() == good
    persistence.load(path)


def test_issue9_item1_imagine_out_on_a_full_disk_keeps_the_earlier_result(tmp_path, monkeypatch):
    from abstract_map.cli import main

    from .test_imagine_command import LION

    out = tmp_path / "r.json"
    out.write_text('{"steps": []}')
    half_writes(monkeypatch)
    with pytest.raises(OSError):
        main(["imagine", str(LION), "--out", str(out), "--quiet"])
    monkeypatch.undo()
    assert out.read_text() == '{"steps": []}'


@given(st.text(max_size=80), st.text(max_size=80))
def test_safe_names_are_plain_file_names_and_unique(a, b):
    for name in (safe_name(a), safe_name(b)):
        assert name and "/" not in name and "\\" not in name and name not in (".", "..")
        assert all(c.isascii() and (c.isalnum() or c in "_~") for c in name)
    assert (safe_name(a) == safe_name(b)) == (a == b)


def test_safe_names_keep_plain_goals_and_separate_look_alikes():
    assert safe_name("Polar bear") == "Polar_bear"
    assert safe_name("Polar_bear") != "Polar_bear"
    assert "/" not in safe_name("../../x") and "." not in safe_name("../../x")
