"""Edits of JSON-like data for property tests: every leaf's path, and a copy with one leaf replaced."""

from __future__ import annotations

import copy
from typing import Any


def leaves(data: Any, prefix: tuple = ()) -> list[list[Any]]:
    """The path (keys and indices) of every node below ``data``, in order."""
    out = [list(prefix)] if prefix else []
    if isinstance(data, dict):
        for key, value in data.items():
            out += leaves(value, prefix + (key,))
    elif isinstance(data, list):
        for i, value in enumerate(data):
            out += leaves(value, prefix + (i,))
    return out


def set_path(data: Any, path: list[Any], value: Any) -> Any:
    """A deep copy of ``data`` with the node at ``path`` replaced by ``value``."""
    data = copy.deepcopy(data)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data
