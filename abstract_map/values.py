"""Frozen dataclasses whose hash is computed once: springs are gathered into sets and dicts on every settle."""

from __future__ import annotations

from typing import Any


class RememberedHash:
    """Mixin for a frozen dataclass: its hash is its fields' hash, computed at construction and never again.

    The hash is not pickled (string hashes differ between processes); it is computed anew on unpickling.
    """

    def __post_init__(self) -> None:
        # a dataclass's __init__ sets its fields in order, so before "_hash" the instance dict holds just them
        object.__setattr__(self, "_hash", hash(tuple(self.__dict__.values())))

    def __hash__(self) -> int:
        return self._hash  # type: ignore[attr-defined, no-any-return]

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state.pop("_hash", None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        for name, value in state.items():
            object.__setattr__(self, name, value)
        RememberedHash.__post_init__(self)
