"""Atomic file writes: every file the project writes goes through here.

A file is written to a temporary file in the same folder and renamed over the
target only once it is complete, so a failure mid-write (an exception, a full
disk, a killed process) leaves the previous file intact, never a truncated one.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

_NEW_FILE_MODE = 0o644  # rw-r--r--: what a plain open() gives under the usual umask (mkstemp gives 0o600)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary path to write ``path``'s new content to; renamed over ``path`` on success.

    The temporary name keeps ``path``'s suffix, so writers that pick a format from it
    (matplotlib, Pillow, imageio) still do. The parent folder is created if needed.
    On an exception the temporary file is removed and ``path`` is left as it was.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    handle, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=f".tmp{target.suffix}", dir=target.parent)
    os.close(handle)
    tmp = Path(name)
    try:
        yield tmp
        with open(tmp, "rb") as written:
            os.fsync(written.fileno())
        os.chmod(tmp, target.stat().st_mode & 0o7777 if target.exists() else _NEW_FILE_MODE)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    write_bytes_atomic(path, text.encode("utf-8"))


def json_text(data: Any, **options: Any) -> str:
    """``data`` as strict JSON: a NaN or infinite float (which JSON cannot hold) is written as null."""
    def clean(value: Any) -> Any:
        if isinstance(value, float) and not math.isfinite(value):
            return None
        if isinstance(value, dict):
            return {k: clean(v) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [clean(v) for v in value]
        return value

    return json.dumps(clean(data), allow_nan=False, **options)


_PLAIN = re.compile(r"[A-Za-z0-9]+(?: [A-Za-z0-9]+)*")


def safe_name(text: str) -> str:
    """A file name for ``text`` (e.g. a goal) that is safe on every system and unique per text.

    Words of letters and digits keep their spelling with spaces as underscores ("Polar bear" ->
    "Polar_bear"); any other text becomes a slug plus a hash of its exact spelling ("Polar_bear" ->
    "Polar_bear~1c5e...", "../../x" -> "x~..."), which no plain name can equal (it has a '~').
    """
    if _PLAIN.fullmatch(text) and len(text) <= 60:
        return text.replace(" ", "_")
    slug = re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_")[:40] or "name"
    return f"{slug}~{hashlib.sha256(text.encode('utf-8', 'surrogatepass')).hexdigest()[:12]}"
