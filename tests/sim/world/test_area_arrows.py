"""``scripts/area_arrows.py``: whether an area's or a sibling's arrow gives the way to the area's rooms."""

from __future__ import annotations

import re

from abstract_map.hierarchy import Hierarchy
from sim.world.data import Tag, load_world
from tests.repo_files import load_file, refused_in_one_line

XML = """<hierarchy><place name="Building">
  <place name="West Wing">
    <place name="Radiology"><place name="X-Ray Room"/><place name="Scan Room"/></place>
    <place name="Pharmacy"/>
  </place>
  <place name="Lobby"/>
</place></hierarchy>"""


def load():
    return load_file("scripts/area_arrows.py", "area_arrows")


def test_an_area_leads_to_every_labelled_room_under_it_and_a_room_to_its_siblings():
    script = load()
    hierarchy = Hierarchy.from_xml_string(XML)
    tags = {i: Tag(i, float(i), 0.0, 0.0, "label", name)
                for i, name in enumerate(["X-Ray Room", "Scan Room", "Pharmacy", "Lobby"])}
    assert script.rooms_led_to("West Wing", hierarchy, tags) == ("area", ["Pharmacy", "Scan Room", "X-Ray Room"])
    assert script.rooms_led_to("Radiology", hierarchy, tags) == ("area", ["Scan Room", "X-Ray Room"])
    assert script.rooms_led_to("X-Ray Room", hierarchy, tags) == ("sibling", ["Scan Room"])
    assert script.rooms_led_to("Building", hierarchy, tags) is None  # the root: no area
    assert script.rooms_led_to("Lobby", hierarchy, tags) is None  # its parent is the root
    assert script.rooms_led_to("Nowhere", hierarchy, tags) is None


def test_the_zoos_area_arrows_lead_to_their_enclosures_and_its_sibling_arrows_do_not(capsys):
    """The zoo's arrows to an area (the Snake House, the Outback Adventure) set off the way of its enclosures;
    an arrow to one enclosure says little of the way to its neighbours (they lie round the zoo's paths)."""
    script = load()
    world = load_world("zoo")
    counts = script.route_agreement(world, Hierarchy.from_xml(world.hierarchy_path))
    area = counts["area", True] + counts["area", False]
    sibling = counts["sibling", True] + counts["sibling", False]
    assert area > 20 and counts["area", False] / area < 0.2
    assert sibling > 10 and 0.25 < counts["sibling", False] / sibling < 0.6
    assert script.main(["--world", "zoo"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^zoo +area +routes +\d+", out, re.MULTILINE) and "share another way" in out


def test_a_world_that_is_not_there_is_one_line_and_exit_2(capsys, tmp_path):
    assert "nowhere" in refused_in_one_line(load().main, ["--world", str(tmp_path / "nowhere")], capsys, "area_arrows")
