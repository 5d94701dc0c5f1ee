"""What an arrow naming an area, or a room of one, says of the area's other rooms: does their route set off its way?

Usage: ``python scripts/area_arrows.py [FIRST LAST]`` (development seeds, default 0 47) or
``python scripts/area_arrows.py --world NAME`` (a world folder or a name under ``worlds/``, e.g. ``zoo``).

For every arrow line of every sign that names an area (a place with rooms under it in the hierarchy, not the
building's root) or a room with siblings (a place whose parent area is not the root), the shortest route on the
floor plan from where the sign's reader stands (:meth:`sim.world.truth.Routes.reading_pose`) to each labelled
room in that area (each labelled sibling), and whether its first leg lies within the signage convention's
tolerance of the arrow (``TruthParams.tolerance_deg``, as ``abstract-map world check`` asks of an arrow's own
place). Prints, per kind, how many routes set off the arrow's way and the share that do not: what
``RouteParams.area_wrong_prob`` stands for, the chance that such an arrow does not lead towards the goal. A room
the same sign also names in an arrow is counted apart (``also named``): there the sign has said where it is.
The seeds are ``generated:FIRST-LAST`` (style and signage cycling with the seed, medium size), so sparse signage,
which names areas, and misleading signage, whose turned arrows the navigator meets too, are both in.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Mapping

from abstract_map.clauses import Locational
from abstract_map.hierarchy import Hierarchy
from sim.experiments.survey import buildings, on_world, survey_parser
from sim.world.data import Tag, World
from sim.world.generator import generate
from sim.world.truth import Routes, first_leg, place_tags

KINDS = ("area", "area, also named", "sibling", "sibling, also named")


def rooms_led_to(name: str, hierarchy: Hierarchy, tags: Mapping[int, Tag]) -> tuple[str, list[str]] | None:
    """The kind of place ``name`` is to an arrow and the rooms with a label among ``tags`` its arrow is read to
    lead towards: ("area", every such place in it, by :func:`sim.world.truth.place_tags`) or ("sibling", the other
    such places of its parent area); None for the building's root or a place whose parent is the root."""
    parent = hierarchy.parent
    if name not in parent:
        return None
    if hierarchy.children(name):
        return "area", sorted({t.text for t in place_tags(name, hierarchy, tags)} - {name})
    area = parent[name]
    if area not in parent:
        return None
    labelled = {t.text for t in tags.values() if t.kind == "label"}
    return "sibling", sorted(p for p, up in parent.items() if up == area and p != name and p in labelled)


def route_agreement(world: World, hierarchy: Hierarchy) -> Counter[tuple[str, bool]]:
    """(kind, whether the route sets off within the tolerance of the arrow) -> how many routes, over every arrow
    of ``world``'s signs naming an area or a room with siblings and every room it is read to lead towards
    (kinds: :data:`KINDS`). Rooms no route reaches, or whose route has no first leg, are left out."""
    routes = Routes(world.floorplan)
    tolerance = routes.params.tolerance_deg
    labels: dict[str, list[Tag]] = defaultdict(list)
    for tag in world.tags.values():
        if tag.kind == "label":
            labels[tag.text].append(tag)
    out: Counter[tuple[str, bool]] = Counter()
    for sign in (t for t in world.tags.values() if t.kind == "sign"):
        arrows = [c for c in sign.clauses() if isinstance(c, Locational) and c.kind == "arrow"]
        pose = routes.reading_pose(sign)
        field_ = None if pose is None else routes.field_from(pose)
        if field_ is None:
            continue
        named = {c.toponym for c in arrows}
        for clause in arrows:
            led = rooms_led_to(clause.toponym, hierarchy, world.tags)
            if led is None:
                continue
            kind, rooms = led
            for room in rooms:
                path = field_.route_to(labels[room])
                leg = None if path is None else first_leg(path, None, routes.params)
                if leg is None:
                    continue
                error = abs(math.degrees(math.remainder(leg - clause.direction, math.tau)))
                out[kind + (", also named" if room in named else ""), error <= tolerance] += 1
    return out


def summary(name: str, counts: Counter[tuple[str, bool]]) -> list[str]:
    """One line per kind with any route: how many routes set off the arrow's way, how many not, and that share."""
    lines = []
    for kind in KINDS:
        right, wrong = counts[kind, True], counts[kind, False]
        if right + wrong:
            lines.append(f"{name:10s} {kind:20s} routes {right + wrong:5d}  the arrow's way {right:5d}  "
                         f"another way {wrong:5d}  share another way {wrong / (right + wrong):.2f}")
    return lines or [f"{name:10s} no arrow names an area or a room with siblings"]


def main(argv: list[str] | None = None) -> int:
    parser = survey_parser(__doc__, (0, 47))
    args = parser.parse_args(argv)
    if args.world:
        counts = on_world(parser, args, "area_arrows",
                          lambda world: route_agreement(world, Hierarchy.from_xml(world.hierarchy_path)))
        print("\n".join(summary(args.world, counts)))
        return 0
    by_level: dict[str, Counter[tuple[str, bool]]] = defaultdict(Counter)
    for building in buildings(parser, args):
        built = generate(building.seed, style=building.style, signage=building.signage)
        by_level[building.signage] += route_agreement(built.world, built.hierarchy)
    lines = summary("all", sum(by_level.values(), Counter()))
    for level, counts in sorted(by_level.items()):
        lines += summary(level, counts)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
