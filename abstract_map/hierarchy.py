"""The spatial hierarchy: which place is in which, and each place's level.

Leaves (rooms, enclosures) are level 1; a parent is one above its highest
child. The hierarchy loads from XML (``<place name="..."> ... </place>``,
parsed with defusedxml, so no entity expansion) or from a nested mapping such
as ``{"Campus": {"A Block": {"Room 1": {}}}}``.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from defusedxml import ElementTree
from defusedxml.common import DefusedXmlException

from .clauses import Relational


class HierarchyError(ValueError):
    """A hierarchy that is malformed: bad XML, a place with two parents, a cycle."""


@dataclass
class Hierarchy:
    """A forest of places; ``parent[child] = parent``."""

    parent: dict[str, str] = field(default_factory=dict)
    places: list[str] = field(default_factory=list)  # every place, in document order

    def add(self, child: str, parent: str, *, where: str = "hierarchy") -> bool:
        """Add the edge child-in-parent; True if it is new."""
        for name in (child, parent):
            if name not in self.places:
                self.places.append(name)
        if child == parent:
            raise HierarchyError(f"{where}: {child!r} cannot be in itself")
        if self.parent.get(child) == parent:
            return False
        if child in self.parent:
            raise HierarchyError(f"{where}: {child!r} is already in {self.parent[child]!r}, not also in {parent!r}")
        node: str | None = parent
        while node is not None:
            if node == child:
                raise HierarchyError(f"{where}: {child!r} in {parent!r} would make a cycle")
            node = self.parent.get(node)
        self.parent[child] = parent
        return True

    def add_place(self, name: str) -> None:
        if name not in self.places:
            self.places.append(name)

    def children(self, name: str) -> list[str]:
        return [c for c in self.places if self.parent.get(c) == name]

    def roots(self) -> list[str]:
        parents = set(self.parent.values())
        return [p for p in self.places if p not in self.parent and p in parents]

    def leaves(self) -> list[str]:
        """Places with no children, in document order."""
        parents = set(self.parent.values())
        return [p for p in self.places if p not in parents]

    def levels(self) -> dict[str, int]:
        """Level of every place: leaves 1, a parent one above its highest child."""
        kids: dict[str, list[str]] = {p: [] for p in self.places}
        for child, parent in self.parent.items():
            kids[parent].append(child)
        level: dict[str, int] = {}

        def visit(name: str) -> int:
            if name not in level:
                level[name] = 1 + max((visit(c) for c in kids[name]), default=0)
            return level[name]

        for name in self.places:
            visit(name)
        return level

    def clauses(self) -> list[Relational]:
        """The hierarchy as "X is in Y" clauses, in document order."""
        return [Relational("in", c, (self.parent[c],)) for c in self.places if c in self.parent]

    def to_nested(self) -> dict[str, Any]:
        kids: dict[str, list[str]] = {p: [] for p in self.places}
        for child in self.places:
            if child in self.parent:
                kids[self.parent[child]].append(child)

        def nest(name: str) -> dict[str, Any]:
            return {c: nest(c) for c in kids[name]}

        return {r: nest(r) for r in self.places if r not in self.parent}

    @classmethod
    def from_nested(cls, data: Mapping[str, Any], *, where: str = "hierarchy") -> Hierarchy:
        """From ``{"Campus": {"A Block": {"Room 1": {}}}}``."""
        hierarchy = cls()

        def walk(node: Mapping[str, Any], parent: str | None) -> None:
            if not isinstance(node, Mapping):
                raise HierarchyError(f"{where}: expected an object of places, got {type(node).__name__}")
            for name, children in node.items():
                if not isinstance(name, str) or not name.strip():
                    raise HierarchyError(f"{where}: a place needs a non-empty name, got {name!r}")
                hierarchy.add_place(name)
                if parent is not None:
                    hierarchy.add(name, parent, where=where)
                walk(children or {}, name)

        walk(data, None)
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
            raise HierarchyError(f"{path}: cannot read hierarchy ({exc})") from exc
        except (ElementTree.ParseError, DefusedXmlException) as exc:
            raise HierarchyError(f"{path}: malformed hierarchy XML ({exc})") from exc
        return cls.from_element(root, where=str(path))

    @classmethod
    def from_xml_string(cls, text: str, *, where: str = "hierarchy XML") -> Hierarchy:
        try:
            root = ElementTree.fromstring(text)
        except (ElementTree.ParseError, DefusedXmlException) as exc:
            raise HierarchyError(f"{where}: malformed hierarchy XML ({exc})") from exc
        return cls.from_element(root, where=where)

    @classmethod
    def from_element(cls, root: Any, *, where: str) -> Hierarchy:
        hierarchy = cls()

        def walk(elements: Iterable[Any], parent: str | None) -> None:
            for element in elements:
                if element.tag != "place":
                    raise HierarchyError(f"{where}: unexpected element <{element.tag}>, expected <place name=...>")
                name = (element.get("name") or "").strip()
                if not name:
                    raise HierarchyError(f"{where}: a <place> has no name attribute")
                hierarchy.add_place(name)
                if parent is not None:
                    hierarchy.add(name, parent, where=where)
                walk(list(element), name)

        top = [root] if root.tag == "place" else list(root)
        walk(top, None)
        if not hierarchy.places:
            raise HierarchyError(f"{where}: no <place> elements")
        return hierarchy
