"""The spatial hierarchy: which place is in which, and each place's level.

Leaves (rooms, enclosures) are level 1; a parent is one above its highest
child. The hierarchy loads from XML (``<place name="..."> ... </place>``,
parsed with defusedxml, so no entity expansion) or from a nested mapping such
as ``{"Campus": {"A Block": {"Room 1": {}}}}``.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from defusedxml import ElementTree
from defusedxml.common import DefusedXmlException

from .clauses import Relational
from .errors import HierarchyError, place_name
from .values import T, remembered

__all__ = ["Hierarchy", "HierarchyError"]


@dataclass
class Hierarchy:
    """A forest of places; ``parent[child] = parent``.

    Every walk over it is iterative, so its depth is bounded only by memory.
    """

    parent: dict[str, str] = field(default_factory=dict)
    places: list[str] = field(default_factory=list)  # every place, in document order

    def __post_init__(self) -> None:
        self._cache: dict[str, tuple[Hashable, Any]] = {}  # derived data by the version it was made at
        self._known = set(self.places)
        self._with_children = set(self.parent.values())
        if len(self._known) != len(self.places):
            raise HierarchyError("hierarchy: a place is listed twice")

    def copy(self) -> Hierarchy:
        return Hierarchy(dict(self.parent), list(self.places))

    def add(self, child: str, parent: str, *, where: str = "hierarchy") -> bool:
        """Add the edge child-in-parent; True if it is new. A refused edge changes nothing."""
        for name in (child, parent):
            place_name(where, name, error=HierarchyError)
        if child == parent:
            raise HierarchyError(f"{where}: {child!r} cannot be in itself")
        if self.parent.get(child) == parent:
            return False
        if child in self.parent:
            raise HierarchyError(f"{where}: {child!r} is already in {self.parent[child]!r}, not also in {parent!r}")
        if child in self._with_children:  # a place with no children cannot be an ancestor of its parent
            node: str | None = parent
            while node is not None:
                if node == child:
                    raise HierarchyError(f"{where}: {child!r} in {parent!r} would make a cycle")
                node = self.parent.get(node)
        for name in (child, parent):
            self.add_place(name)
        self.parent[child] = parent
        self._with_children.add(parent)
        return True

    def add_place(self, name: str, *, where: str = "hierarchy") -> None:
        if name not in self._known:
            place_name(where, name, error=HierarchyError)
            self._known.add(name)
            self.places.append(name)

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in self._known

    def children(self, name: str) -> list[str]:
        return [c for c in self.places if self.parent.get(c) == name]

    def roots(self) -> list[str]:
        parents = set(self.parent.values())
        return [p for p in self.places if p not in self.parent and p in parents]

    def leaves(self) -> list[str]:
        """Places with no children, in document order."""
        parents = set(self.parent.values())
        return [p for p in self.places if p not in parents]

    @property
    def version(self) -> tuple[int, int]:
        """Changes whenever the hierarchy does (it only grows: edges and places are never removed)."""
        return len(self.parent), len(self.places)

    def _cached(self, key: str, make: Callable[[], T]) -> T:
        return remembered(self._cache, key, self.version, make)

    def levels(self) -> dict[str, int]:
        """Level of every place: leaves 1, a parent one above its highest child (a shared table: do not change)."""
        return self._cached("levels", self._levels)

    def _levels(self) -> dict[str, int]:
        pending = dict.fromkeys(self.places, 0)  # children not yet levelled
        for parent in self.parent.values():
            pending[parent] += 1
        level = dict.fromkeys(self.places, 1)
        ready = [p for p in self.places if pending[p] == 0]
        while ready:
            name = ready.pop()
            parent = self.parent.get(name)
            if parent is not None:
                level[parent] = max(level[parent], level[name] + 1)
                pending[parent] -= 1
                if pending[parent] == 0:
                    ready.append(parent)
        return level

    def clauses(self) -> list[Relational]:
        """The hierarchy as "X is in Y" clauses, in document order (a shared list: do not change)."""
        return self._cached("clauses", lambda: [Relational("in", c, (self.parent[c],))
                                                for c in self.places if c in self.parent])

    def to_nested(self) -> dict[str, Any]:
        nodes: dict[str, dict[str, Any]] = {p: {} for p in self.places}
        for child in self.places:
            if child in self.parent:
                nodes[self.parent[child]][child] = nodes[child]
        return {r: nodes[r] for r in self.places if r not in self.parent}

    @classmethod
    def from_nested(cls, data: Mapping[str, Any], *, where: str = "hierarchy") -> Hierarchy:
        """From ``{"Campus": {"A Block": {"Room 1": {}}}}``."""
        hierarchy = cls()
        if not isinstance(data, Mapping):
            raise HierarchyError(f"{where}: expected an object of places, got {type(data).__name__}")
        # depth first, in document order: (name, its children, its parent)
        stack: list[tuple[Any, Any, str | None]] = [(n, c, None) for n, c in reversed(data.items())]
        while stack:
            name, children, parent = stack.pop()
            hierarchy.add_place(name, where=where)
            if parent is not None:
                hierarchy.add(name, parent, where=where)
            children = {} if children is None else children
            if not isinstance(children, Mapping):
                raise HierarchyError(f"{where}: the places in {name!r} must be an object, "
                                     f"got {type(children).__name__}")
            stack.extend((n, c, name) for n, c in reversed(children.items()))
        if not hierarchy.places:
            raise HierarchyError(f"{where}: no places")
        return hierarchy

    @classmethod
    def from_xml(cls, source: str | os.PathLike[str]) -> Hierarchy:
        """From an XML file of nested ``<place name="...">`` elements."""
        path = Path(source)
        try:
            root = ElementTree.parse(str(path)).getroot()
        except OSError as exc:
            raise HierarchyError(f"{path}: cannot read hierarchy ({exc.strerror or exc})") from exc
        except (ElementTree.ParseError, DefusedXmlException, ValueError) as exc:
            raise HierarchyError(f"{path}: malformed hierarchy XML ({exc})") from exc
        return cls.from_element(root, where=str(path))

    @classmethod
    def from_xml_string(cls, text: str, *, where: str = "hierarchy XML") -> Hierarchy:
        try:
            root = ElementTree.fromstring(text)
        except (ElementTree.ParseError, DefusedXmlException, ValueError) as exc:
            raise HierarchyError(f"{where}: malformed hierarchy XML ({exc})") from exc
        return cls.from_element(root, where=where)

    @classmethod
    def from_element(cls, root: Any, *, where: str) -> Hierarchy:
        hierarchy = cls()
        top = [root] if root.tag == "place" else list(root)
        stack: list[tuple[Any, str | None]] = [(e, None) for e in reversed(top)]  # depth first, document order
        while stack:
            element, parent = stack.pop()
            if element.tag != "place":
                raise HierarchyError(f"{where}: unexpected element <{element.tag}>, expected <place name=...>")
            name = (element.get("name") or "").strip()
            if not name:
                raise HierarchyError(f"{where}: a <place> has no name attribute")
            hierarchy.add_place(name, where=where)
            if parent is not None:
                hierarchy.add(name, parent, where=where)
            stack.extend((e, name) for e in reversed(list(element)))
        if not hierarchy.places:
            raise HierarchyError(f"{where}: no <place> elements")
        return hierarchy
