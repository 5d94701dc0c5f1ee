"""Computing once what is asked for often: derived data until its inputs change, and frozen values' hashes."""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from operator import attrgetter
from typing import Any, Generic, TypeVar

T = TypeVar("T")
S = TypeVar("S")


def remembered(cache: dict[str, tuple[Hashable, Any]], key: str, version: Hashable, make: Callable[[], T]) -> T:
    """``make()``, kept in ``cache`` under ``key`` and made again only when ``version`` differs from the one it
    was made at. The value is shared: callers must not change it."""
    hit = cache.get(key)
    if hit is None or hit[0] != version:
        hit = cache[key] = (version, make())
    return hit[1]  # type: ignore[no-any-return]


class RememberedHash:
    """Mixin for a frozen dataclass: its hash is its fields' hash, computed at construction and never again,
    and ``fields`` is the tuple of its fields (a sort key that no hash order decides). A subclass must say
    ``__hash__ = RememberedHash.__hash__`` in its body, or the dataclass writes its own.

    The hash is not pickled (string hashes differ between processes); it is computed anew on unpickling.
    """

    def __post_init__(self) -> None:
        # a dataclass's __init__ sets its fields in order, so before "fields" the instance dict holds just them
        fields = tuple(self.__dict__.values())
        object.__setattr__(self, "fields", fields)
        object.__setattr__(self, "_hash", hash(fields))

    def __hash__(self) -> int:
        return self._hash  # type: ignore[attr-defined, no-any-return]

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state.pop("_hash", None)
        state.pop("fields", None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        for name, value in state.items():
            object.__setattr__(self, name, value)
        RememberedHash.__post_init__(self)


FIELDS = attrgetter("fields")  # the sort key of a RememberedHash value


class GrowingFold(Generic[T, S]):
    """A fold over a list that mostly grows at its end (the clauses of a model, cue after cue).

    ``fold(state, items)`` folds ``items`` into ``state``, which ``start()`` makes empty. Called with a list
    whose start is the list it was last called with (the same objects, in order), only the items added since
    are folded; with any other list it starts again. The state is shared: callers must not change it.
    """

    def __init__(self, start: Callable[[], S], fold: Callable[[S, Sequence[T]], None]) -> None:
        self._start, self._fold = start, fold
        self._items: list[T] = []
        self._state: S = start()

    def __call__(self, items: Sequence[T]) -> S:
        done = len(self._items)
        if len(items) < done or list(items[:done]) != self._items:  # compares identity first: cheap when equal
            self._state, done = self._start(), 0
        self._fold(self._state, items[done:])
        self._items = list(items)
        return self._state
