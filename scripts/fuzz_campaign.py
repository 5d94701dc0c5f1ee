"""A campaign of malformed and hostile inputs, counting outcomes per surface (issue 9).

Usage:
  python scripts/fuzz_campaign.py                 # every surface, about 10 minutes on 2 cores
  python scripts/fuzz_campaign.py --quick         # a tenth of the random inputs, about 2 minutes
  python scripts/fuzz_campaign.py --surfaces cue scenario --json campaign.json

Surfaces: cue text (the Python API), scenario (``abstract-map imagine``), saved
model (``persistence.load``), world folder (``load_world``), arguments (the
``trial``, ``study`` and ``imagine`` commands, as subprocesses) and study resume.
Inputs are drawn from a seeded generator, so a run is reproducible.

Each input ends in one outcome:

- ok: it worked, and everything it produced is finite, valid JSON;
- clean error: the project's own error (API), or exit 2 with one line and no traceback (command line);
- traceback: any other exception, or a traceback printed by a command;
- wrong: a silent wrong answer: accepted although out of spec, NaN or invalid JSON out, a model left
  broken by a refused cue, or a cue accepted that breaks the next settle;
- lost: a file that was good before is truncated or gone afterwards (including under a simulated full disk);
- slow: over the per-input time limit (item 8 of the issue).

It runs against whatever ``abstract_map`` and ``sim`` are importable, so
``PYTHONPATH=/path/to/old/tree python scripts/fuzz_campaign.py`` measures an older version.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import io
import json
import logging
import math
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

OUTCOMES = ("ok", "clean", "traceback", "wrong", "lost", "slow")
LIMIT_S = 20.0  # CPU seconds per in-process input (CPU, not wall: other work on the machine does not count)
HOSTILE: list[Any] = [None, True, False, "abc", "", " ", "\x00", "#start", "#3", "NaN", 1.7e308, -1.7e308, 1e300,
                      10**400, -(10**400), float("nan"), float("inf"), float("-inf"), -5, 0, -0.0, 17.9, 2**70, [],
                      {}, [1, 2], [1, 2, 3], [1, 2, 3, 4], ["a", "b", "c"], {"a": 1}, "x" * 5000, "Ünïcødé ☃", -1]


def project_errors() -> tuple[type[BaseException], ...]:
    """The project's own exception types, whichever this version has."""
    found: list[type[BaseException]] = []
    for module, names in (("abstract_map.errors", ["AbstractMapError"]), ("abstract_map.grammar", ["CueError"]),
                          ("abstract_map.hierarchy", ["HierarchyError"]),
                          ("abstract_map.scenario", ["ScenarioError"]),
                          ("abstract_map.persistence", ["ModelFileError"]),
                          ("abstract_map.model", ["UnknownPlaceError"]),
                          ("abstract_map.cli", ["ExitError"]), ("sim.world.data", ["WorldError"])):
        try:
            mod = __import__(module, fromlist=names)
        except ImportError:
            continue
        found += [getattr(mod, n) for n in names if hasattr(mod, n)]
    return tuple(found)


class Timeout(Exception):
    pass


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    def handler(signum: int, frame: Any) -> None:
        raise Timeout()

    old = signal.signal(signal.SIGPROF, handler)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, old)


def finite_json(text: str) -> bool:
    """Strict JSON (no NaN/Infinity tokens) whose numbers are all finite."""
    def bad(token: str) -> Any:
        raise ValueError(token)
    try:
        data = json.loads(text, parse_constant=bad)
    except ValueError:
        return False
    stack = [data]
    while stack:
        item = stack.pop()
        if isinstance(item, float) and not math.isfinite(item):
            return False
        if isinstance(item, dict):
            stack.extend(item.values())
        elif isinstance(item, list):
            stack.extend(item)
    return True


def finite_model(model: Any) -> bool:
    return all(np.all(np.isfinite(xy)) for xy in model.positions.values())


def snapshot(model: Any) -> str:
    from abstract_map.persistence import to_dict

    return json.dumps(to_dict(model), sort_keys=True, default=str)


def cli(argv: list[str]) -> tuple[int | str, str]:
    """Run the command line in this process: (exit code or 'traceback', stderr)."""
    from abstract_map.cli import main

    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code: int | str = main(argv)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 2
    except Timeout:
        raise
    except BaseException as exc:  # noqa: BLE001  # what the campaign is looking for
        return "traceback", f"{type(exc).__name__}: {exc}"
    return code, err.getvalue()


def one_clean_line(stderr: str) -> bool:
    """One line of stderr, no traceback (pybullet's own banner, printed as it is imported, is not ours)."""
    lines = [line for line in stderr.strip().splitlines() if line.strip() and not line.startswith("pybullet build")]
    return len(lines) == 1 and "Traceback" not in stderr


# -- cue text -----------------------------------------------------------------------

GOOD_NAMES = ["Lion", "lion", "the Lion", "Giraffe", "X", "Y", "Zoo", "Polar bear", "here", "Ünïcødé Place", "A", "B",
              "Kiosk", "the Toilets", "Room 2"]
BAD_NAMES = ["#start", "#3", "", "a" * 300, "Room\t2", "$LEFT$", "is", "and", "."]
PREPS = ["past", "after", "beyond", "before", "towards", "left of", "right of", "to the left of", "near", "beside",
         "by", "with", "next to", "between", "in", "inside", "within", "under", "above", "is"]
ARROWS = ["LEFT", "RIGHT", "UP", "DOWN", "left", "SIDEWAYS", ""]


def cue_text(rng: random.Random) -> str:
    n = lambda: rng.choice(GOOD_NAMES if rng.random() < 0.9 else BAD_NAMES)  # noqa: E731
    line = lambda: rng.choice([  # noqa: E731
        f"{n()} is {rng.choice(PREPS)} {n()}",
        f"{n()} is between {n()} and {n()}",
        f"from {n()}, {n()} is {rng.choice(PREPS)} {n()}",
        f"{n()} and {n()} are {rng.choice(PREPS)} {n()}",
        f"${rng.choice(ARROWS)}$ {n()}, {n()} and {n()}",
        f"${rng.choice(ARROWS)}$ {n()}",
        n(),
    ])
    kind = rng.random()
    if kind < 0.03:
        return "$LEFT$ " + ", ".join(f"P{i}" for i in range(rng.choice([300, 1000])))
    if kind < 0.06:
        return "\n".join(f"P{i + 1} is past P{i}" for i in range(rng.choice([100, 300])))
    if kind < 0.12:
        return "".join(rng.choice("abc $#,.\n\\\x00\x7f☃ is near past LEFT") for _ in range(rng.randint(0, 80)))
    return "\n".join(line() for _ in range(rng.randint(1, 4)))


def cue_inputs(rng: random.Random, count: int) -> Iterator[dict[str, Any]]:
    fixed = ["X is past here", "X is left of here", "X is near X", "X is between Y and Y",
             "X is near Y", "Lion is in Giraffe\nGiraffe is in Lion", "#start", "#3 is near Lion"]
    for text in fixed:
        yield {"text": text, "tag": 7, "pose": [0.0, 5.0, -math.pi / 2], "kind": None}
    for _ in range(count - len(fixed)):
        pose: list[Any] = [rng.uniform(-30, 30), rng.uniform(-30, 30), rng.uniform(-4, 4)]
        if rng.random() < 0.1:
            pose[rng.randrange(3)] = rng.choice(HOSTILE)
        tag: Any = rng.randrange(20) if rng.random() > 0.1 else rng.choice(HOSTILE)
        kind = rng.choice([None, None, None, "label", "sign", "bogus"])
        yield {"text": cue_text(rng) if rng.random() > 0.05 else rng.choice(HOSTILE), "tag": tag, "pose": pose,
               "kind": kind, "untagged": rng.random() < 0.25, "goal": rng.choice([None, None, "Lion", 3, "#start"])}


def run_cue(case: dict[str, Any], errors: tuple[type[BaseException], ...]) -> str:
    from abstract_map.grammar import parse_cue
    from abstract_map.hierarchy import Hierarchy
    from abstract_map.model import AbstractMap

    model = AbstractMap.from_hierarchy(Hierarchy.from_nested({"Zoo": {"Lion": {}, "Giraffe": {}}}),
                                       (0.0, 0.0, math.pi / 2))
    model.set_explored_centre((0.0, 0.0))
    model.settle()
    before = snapshot(model)
    try:
        if case.get("untagged"):
            model.add_clauses(parse_cue(case["text"], kind=case["kind"]))
        else:
            model.observe_tag(case["tag"], case["text"], case["pose"], kind=case["kind"])
        before = snapshot(model)
        if case.get("goal") is not None:
            model.set_goal(case["goal"])
    except errors:
        if snapshot(model) != before:
            return "wrong"  # a refused cue changed the model
        try:
            model.settle()
        except Exception:  # noqa: BLE001
            return "wrong"
        return "clean"
    except Timeout:
        raise
    except Exception:  # noqa: BLE001
        return "traceback"
    try:
        for _ in range(2):
            model.settle()
    except Timeout:
        raise
    except Exception:  # noqa: BLE001  # an accepted cue broke the model
        return "traceback"
    if not finite_model(model):
        return "wrong"
    if max((float(np.hypot(*xy)) for xy in model.positions.values()), default=0.0) > 5000.0:
        return "wrong"  # drifted off: the model lives within a few hundred metres
    return "ok"


# -- scenario -----------------------------------------------------------------------

GOOD_SCENARIO = {"hierarchy": {"Campus": {"A Block": {"Room 1": {}}}}, "start": [0, 0, 90], "goal": "Room 1",
                 "steps": [{"text": "$LEFT$ Room 1", "tag": 1, "pose": [0, 2, -90]},
                           {"text": "Room 2 is near Room 1"}]}


def paths_of(data: Any, prefix: tuple = ()) -> list[tuple]:
    out = [prefix]
    if isinstance(data, dict):
        for k, v in data.items():
            out += paths_of(v, prefix + (k,))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            out += paths_of(v, prefix + (i,))
    return out


def mutate(data: Any, rng: random.Random, times: int = 1) -> Any:
    """Set a random place of ``data`` to a hostile value, delete it, or add an unknown key."""
    data = copy.deepcopy(data)
    for _ in range(times):
        path = rng.choice(paths_of(data)[1:])
        parent = data
        for key in path[:-1]:
            parent = parent[key]
        action = rng.random()
        if action < 0.75:
            parent[path[-1]] = copy.deepcopy(rng.choice(HOSTILE))
        elif action < 0.9 and isinstance(parent, dict):
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[path[-1] + "z" if isinstance(path[-1], str) else "extra"] = 1
    return data


def deep(depth: int) -> dict[str, Any]:
    node: dict[str, Any] = {}
    top = node
    for i in range(depth):
        node[f"L{i}"] = {}
        node = node[f"L{i}"]
    node["Room 1"] = {}
    return top


def scenario_inputs(rng: random.Random, count: int) -> Iterator[tuple[str, Any]]:
    g = GOOD_SCENARIO
    fixed: list[Any] = [
        {**g, "start": [1.7e308, 0, 90]}, {**g, "start": [1e300, 0, 90]}, {**g, "start": [10**400, 0, 0]},
        {**g, "hierarchy": deep(600)}, {**g, "hierarchy": {"#start": {"Room 1": {}}}},
        {**g, "hierarchy": {"#3": {"Room 1": {}}}}, {**g, "goal": 3}, {**g, "goal": "#start"},
        {**g, "steps": [{"text": "X is past here", "tag": 1, "pose": [0, 2, 0]}]},
        {**g, "steps": [{"text": "X is near X"}]}, {**g, "steps": [{"text": "A", "tag": 1.5, "pose": [0, 1, 0]}]},
        {**g, "steps": [{"text": "A", "tag": 1, "pose": [0, 1, 0], "kind": "bogus"}]},
        {**g, "steps": [{"text": "A", "tag": 1, "pose": [0, 1, 0], "explored_centre": [1e308, 0]}]},
        {**g, "hierarchy": "../../../../etc/passwd"}, {**g, "hierarchy": "."},
    ]
    for data in fixed:
        yield "json", data
    for text in ["", "{", "\xff\xfe", "[" * 100000 + "]" * 100000, "null", "[]", '{"hierarchy": 1}',
                 json.dumps(g)[:40]]:
        yield "text", text
    for _ in range(count - len(fixed) - 8):
        yield "json", mutate(g, rng, times=rng.choice([1, 1, 2, 3]))


def run_scenario(case: tuple[str, Any], folder: Path) -> str:
    kind, data = case
    path = folder / "s.json"
    out = folder / "r.json"
    out.write_text('{"steps": "an earlier good result"}')
    if kind == "text":
        path.write_bytes(data.encode("utf-8", "surrogateescape") if isinstance(data, str) else data)
    else:
        path.write_text(json.dumps(data, allow_nan=True))
    code, err = cli(["imagine", str(path), "--out", str(out), "--quiet"])
    if code == "traceback" or "Traceback" in err:
        return "traceback"
    if code == 0:
        return "ok" if finite_json(out.read_text()) else "wrong"
    if out.read_text() != '{"steps": "an earlier good result"}':
        return "lost"
    return "clean" if code == 2 and one_clean_line(err) else "traceback"


# -- saved model --------------------------------------------------------------------

def good_model() -> dict[str, Any]:
    from abstract_map.hierarchy import Hierarchy
    from abstract_map.model import AbstractMap
    from abstract_map.persistence import to_dict

    model = AbstractMap.from_hierarchy(Hierarchy.from_nested({"Zoo": {"Lion": {}, "Giraffe": {}}}),
                                       (0.0, 0.0, math.pi / 2), goal="Lion")
    model.set_explored_centre((0.0, 0.0))
    model.settle()
    model.observe_tag(3, "$UP$ Giraffe\nThe Lion is past the Giraffe", (0.0, 5.0, -math.pi / 2))
    model.add_clauses([])
    model.settle()
    return json.loads(json.dumps(to_dict(model)))


def model_inputs(rng: random.Random, count: int) -> Iterator[Any]:
    good = good_model()
    first = [mutate(good, rng) for _ in range(0)]
    nan = copy.deepcopy(good)
    nan["positions"]["Lion"] = [float("nan"), 0.0]
    inf = copy.deepcopy(good)
    inf["exploration_factor"] = float("inf")
    kind = copy.deepcopy(good)
    kind["fixed"]["#3"]["kind"] = "billboard"
    first += [nan, inf, kind, [], None, {**good, "hierarchy": []}, {**good, "fixed": []}]
    yield from first
    for _ in range(count - len(first)):
        yield mutate(good, rng, times=rng.choice([1, 1, 2]))


def run_model(data: Any, folder: Path, errors: tuple[type[BaseException], ...]) -> str:
    from abstract_map.persistence import load

    path = folder / "m.json"
    path.write_text(json.dumps(data, allow_nan=True))
    try:
        model = load(path)
    except errors:
        return "clean"
    except Timeout:
        raise
    except Exception:  # noqa: BLE001
        return "traceback"
    try:
        model.settle()
        if model.goal is not None:
            model.goal_estimate()
    except Timeout:
        raise
    except Exception:  # noqa: BLE001  # a model that loads must work
        return "traceback"
    return "ok" if finite_model(model) else "wrong"


def disk_full(kind: str, folder: Path) -> str:
    """A write that fails half-way (file size limit) must leave the earlier file whole."""
    target = folder / f"full-{kind}.json"
    target.write_text('{"earlier": "good"}')
    code = f"""
import resource, signal, sys, json, math
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (600, 600))
target = {str(target)!r}
if {kind!r} == "model":
    from abstract_map.hierarchy import Hierarchy
    from abstract_map.model import AbstractMap
    from abstract_map.persistence import save
    m = AbstractMap.from_hierarchy(Hierarchy.from_nested({{"Zoo": {{"Lion": {{}}, "Giraffe": {{}}}}}}), (0, 0, 1.0))
    m.settle()
    save(m, target)
elif {kind!r} == "imagine":
    from abstract_map.cli import main
    sys.exit(main(["imagine", {str(Path(__file__).resolve().parents[1] / "worlds/zoo/lion_replay.json")!r},
                   "--out", target, "--quiet"]))
elif {kind!r} == "csv":
    try:
        from sim.experiments.study import write_csv
    except ImportError:
        from sim.study import write_csv
    from pathlib import Path
    write_csv([{{"goal": f"G{{i}}", "seed": i, "success": True}} for i in range(100)], Path(target))
"""
    subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=600, cwd=folder)
    return "ok" if target.read_text() == '{"earlier": "good"}' or finite_json(target.read_text()) else "lost"


# -- world folder -------------------------------------------------------------------

def write_tiny_world(root: Path, *, extra_goals: dict[str, int] | None = None) -> Path:
    """The tests' tiny world (10 m x 8 m, 0.05 m/px), optionally with more label tags as goals."""
    from PIL import Image

    root.mkdir(parents=True, exist_ok=True)
    image = np.full((160, 200), 255, dtype=np.uint8)
    image[:4, :] = image[-4:, :] = image[:, :4] = image[:, -4:] = 0
    image[60:, 120:124] = 0
    Image.fromarray(image).save(root / "floorplan.png")
    tags = [{"id": 0, "x_m": 6.0, "y_m": 2.5, "theta_deg": 180.0, "kind": "label", "text": "A"},
            {"id": 1, "x_m": 3.0, "y_m": 6.0, "theta_deg": 90.0, "kind": "sign", "text": "$UP$ A"},
            {"id": 2, "x_m": 7.5, "y_m": 2.5, "theta_deg": 180.0, "kind": "sign", "text": "$LEFT$ A"},
            {"id": 3, "x_m": 6.2, "y_m": 1.0, "theta_deg": 0.0, "kind": "empty", "text": ""}]
    places = '<place name="A"/>'
    goals = {"A": 0}
    for i, (goal, tag_id) in enumerate((extra_goals or {}).items()):
        tags.append({"id": tag_id, "x_m": 2.0 + i, "y_m": 3.0, "theta_deg": -90.0, "kind": "label", "text": goal})
        places += f'<place name="{goal}"/>'
        goals[goal] = tag_id
    (root / "tags.json").write_text(json.dumps({"name": "tiny", "tags": tags}, indent=1))
    (root / "hierarchy.xml").write_text(f'<hierarchy><place name="Campus">{places}</place></hierarchy>\n')
    meta = {"format": "abstract-map-world/1", "name": "tiny", "title": "Tiny test building",
            "floorplan": {"image": "floorplan.png", "resolution_m": 0.05, "origin_m": [0.0, 0.0],
                          "occupied_thresh": 0.65, "free_thresh": 0.2, "negate": False},
            "tags": "tags.json", "hierarchy": "hierarchy.xml", "start": {"x_m": 2.0, "y_m": 2.0, "heading_deg": 0.0},
            "goals": goals, "tag": {"size_m": 0.25, "height_m": 1.1}, "walls": {"height_m": 2.0}}
    (root / "world.json").write_text(json.dumps(meta, indent=2))
    return root


def world_inputs(rng: random.Random, count: int) -> Iterator[tuple[str, Callable[[Path], None], bool | None]]:
    """(name, mutation of a tiny world folder, whether the result is within the spec, None if unknown)."""
    def meta(fn: Callable[[dict], None]) -> Callable[[Path], None]:
        def apply(root: Path) -> None:
            data = json.loads((root / "world.json").read_text())
            fn(data)
            (root / "world.json").write_text(json.dumps(data, allow_nan=True))
        return apply

    def tags(fn: Callable[[dict], None]) -> Callable[[Path], None]:
        def apply(root: Path) -> None:
            data = json.loads((root / "tags.json").read_text())
            fn(data)
            (root / "tags.json").write_text(json.dumps(data, allow_nan=True))
        return apply

    def write(name: str, content: bytes) -> Callable[[Path], None]:
        return lambda root: (root / name).write_bytes(content)

    def png(size: tuple[int, int]) -> Callable[[Path], None]:
        def apply(root: Path) -> None:
            from PIL import Image
            Image.fromarray(np.full(size, 255, dtype=np.uint8)).save(root / "floorplan.png")
        return apply

    chain = "".join(f'<place name="L{i}">' for i in range(600)) + "</place>" * 600
    fixed: list[tuple[str, Callable[[Path], None], bool | None]] = [
        ("unchanged", lambda root: None, True),
        ("start abc", meta(lambda d: d.update(start="abc")), False),
        ("start missing x_m", meta(lambda d: d["start"].pop("x_m")), False),
        ("png 0 bytes", write("floorplan.png", b""), False),
        ("png corrupt", write("floorplan.png", b"\x89PNG\r\n\x1a\n" + b"junk" * 100), False),
        ("png 1x1", png((1, 1)), False),
        ("tags []", meta(lambda d: d.update(tags=[])), False),
        ("goals null", meta(lambda d: d.update(goals=None)), False),
        ("goals {}", meta(lambda d: d.update(goals={})), False),
        ("negative resolution", meta(lambda d: d["floorplan"].update(resolution_m=-0.05)), False),
        ("NaN thresholds", meta(lambda d: d["floorplan"].update(occupied_thresh=float("nan"))), False),
        ("null tag text", tags(lambda d: d["tags"][1].update(text=None)), False),
        ("goal id 17.9", meta(lambda d: d["goals"].update(A=17.9)), False),
        ("goal id 0.0", meta(lambda d: d["goals"].update(A=0.0)), False),
        ("goal not in hierarchy", write("hierarchy.xml", b'<place name="Campus"><place name="B"/></place>'), False),
        ("hierarchy 600 deep", write("hierarchy.xml", f'<hierarchy>{chain}</hierarchy>'.replace(
            '<place name="L599">', '<place name="L599"><place name="A"/>').encode()), True),
        ("sign past here", tags(lambda d: d["tags"][1].update(text="X is past here")), False),
        ("sign near itself", tags(lambda d: d["tags"][1].update(text="X is near X")), False),
        ("label #start", tags(lambda d: d["tags"][1].update(kind="label", text="#start")), False),
        ("start in a wall", meta(lambda d: d["start"].update(x_m=0.05, y_m=0.05)), False),
        ("hierarchy cycle via signs", tags(lambda d: d["tags"][1].update(text="A is in B\nB is in A")), False),
        ("entity bomb", write("hierarchy.xml", b'<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "aaaa">'
                              b'<!ENTITY b "&a;&a;&a;&a;">]><place name="&b;"/>'), False),
        ("tag id 9999", tags(lambda d: d["tags"][0].update(id=9999)), False),
        ("duplicate tag ids", tags(lambda d: d["tags"][1].update(id=0)), False),
        ("world.json not JSON", write("world.json", b"{nope"), False),
        ("tags.json deep", write("tags.json", b"[" * 100000 + b"]" * 100000), False),
        ("image outside folder", meta(lambda d: d["floorplan"].update(image="../../../etc/passwd")), False),
    ]
    yield from fixed
    for i in range(count - len(fixed)):
        target = rng.choice(["world", "world", "tags"])
        seed = rng.randrange(2**31)
        if target == "world":
            yield (f"random world.json #{i}", meta(lambda d, s=seed: _replace(d, mutate(d, random.Random(s)))), None)
        else:
            yield (f"random tags.json #{i}", tags(lambda d, s=seed: _replace(d, mutate(d, random.Random(s)))), None)


def _replace(target: dict, new: Any) -> None:
    target.clear()
    if isinstance(new, dict):
        target.update(new)


def run_world(case: tuple[str, Callable[[Path], None], bool | None], folder: Path,
              errors: tuple[type[BaseException], ...]) -> str:
    from sim.world.data import load_world

    name, change, valid = case
    root = folder / "w"
    shutil.rmtree(root, ignore_errors=True)
    write_tiny_world(root)
    change(root)
    try:
        world = load_world(root)
    except errors:
        return "traceback" if valid else "clean"
    except Timeout:
        raise
    except Exception:  # noqa: BLE001
        return "traceback"
    if valid is False:
        return "wrong"  # out of spec, but accepted
    try:  # what a trial does first: the hierarchy, every tag read, the goals set
        from abstract_map.hierarchy import Hierarchy
        from abstract_map.model import AbstractMap

        model = AbstractMap.from_hierarchy(Hierarchy.from_xml(world.hierarchy_path), world.start)
        for tag in world.tags.values():
            if tag.kind != "empty":
                model.observe_tag(tag.id, tag.text, (tag.x, tag.y, tag.theta), kind=tag.kind)
        for goal in world.goals:
            model.set_goal(goal)
        model.settle()
        plan = world.floorplan
        if not (plan.resolution > 0 and np.all(np.isfinite(plan.extent)) and min(plan.shape) > 1
                and world.goals and all(isinstance(v, int) for v in world.goals.values())):
            return "wrong"
    except Timeout:
        raise
    except Exception:  # noqa: BLE001  # accepted at load, fails later
        return "traceback"
    return "ok" if finite_model(model) else "wrong"


# -- command arguments and study resume (subprocesses) ------------------------------

def run_command(argv: list[str], timeout: float = 600.0) -> tuple[int | str, str]:
    try:
        # cwd outside any checkout: "python -m" puts its cwd first on sys.path, ahead of PYTHONPATH
        done = subprocess.run([sys.executable, "-m", "abstract_map.cli", *argv], capture_output=True, text=True,
                              timeout=timeout, cwd=tempfile.gettempdir())
    except subprocess.TimeoutExpired:
        return "timeout", ""
    return done.returncode, done.stderr


def argument_inputs(folder: Path) -> list[tuple[str, list[str], bool, Callable[[], str | None] | None]]:
    """(name, argv, valid, check after the run returning an outcome override or None)."""
    world = str(write_tiny_world(folder / "tiny"))
    scenario = folder / "s.json"
    scenario.write_text(json.dumps(GOOD_SCENARIO))
    a_file = folder / "a-file"
    a_file.write_text("keep me")
    keep = lambda: None if a_file.read_text() == "keep me" else "lost"  # noqa: E731
    trial = ["trial", "--world", world, "--goal", "A", "--perception", "geometric"]
    cases: list[tuple[str, list[str], bool, Callable[[], str | None] | None]] = [
        ("trial ok", [*trial, "--max-sim-s", "30", "--out", str(folder / "t-ok")], True, None),
        ("trial --out an existing file", [*trial, "--max-sim-s", "30", "--out", str(a_file)], False, keep),
        ("trial --out under a file", [*trial, "--out", str(a_file / "x")], False, keep),
    ]
    for value in ["-5", "0", "nan", "inf", "1e400", "abc", "-inf"]:
        cases.append((f"trial --max-sim-s {value}", [*trial, "--max-sim-s", value, "--out", str(folder / "t")],
                      False, None))
    for value in ["-1", "abc", "1.5", str(2**70)]:
        cases.append((f"trial --seed {value}", [*trial, "--seed", value, "--out", str(folder / "t")], False, None))
    for goal in ["", "#3", "Nope", " A"]:
        cases.append((f"trial --goal {goal!r}", ["trial", "--world", world, "--goal", goal, "--perception",
                                                   "geometric", "--out", str(folder / "t")], False, None))
    for w in [str(folder / "nowhere"), "", "/dev/null", str(a_file)]:
        cases.append((f"trial --world {w!r}", ["trial", "--world", w, "--goal", "A", "--out", str(folder / "t")],
                      False, None))
    imagine = ["imagine", str(scenario)]
    cases += [
        ("imagine ok", [*imagine, "--out", str(folder / "i.json"), "--plot", str(folder / "i.png")], True, None),
        ("imagine --out a folder", [*imagine, "--out", str(folder)], False, None),
        ("imagine --out under a file", [*imagine, "--out", str(a_file / "r.json")], False, keep),
        ("imagine --plot x.xyz", [*imagine, "--out", str(folder / "i2.json"), "--plot", str(folder / "p.xyz")],
         False, None),
        ("imagine --save-model = --out", [*imagine, "--out", str(folder / "i3.json"), "--save-model",
                                          str(folder / "i3.json")], False, None),
        ("imagine missing scenario", ["imagine", str(folder / "nope.json"), "--out", str(folder / "i4.json")],
         False, None),
        ("imagine --out = scenario", [*imagine, "--out", str(scenario)], False, None),
    ]
    study = ["study", "--world", world, "--perception", "geometric"]
    for flag, value in [("--trials", "0"), ("--trials", "-1"), ("--trials", "abc"), ("--trials", "1000000"),
                        ("--workers", "0"), ("--workers", "-3"), ("--executor", "bogus")]:
        cases.append((f"study {flag} {value}", [*study, flag, value, "--out", str(folder / "st")], False, None))
    cases += [
        ("study --goals Nope", [*study, "--goals", "Nope", "--out", str(folder / "st")], False, None),
        ("study --address with process", [*study, "--address", "x:1", "--out", str(folder / "st")], False, None),
        ("study --out an existing file", [*study, "--trials", "1", "--out", str(a_file)], False, keep),
    ]
    return cases


DETAILS: dict[str, str] = {}  # case name -> the end of its stderr, for the report of failures


def run_argument(case: tuple[str, list[str], bool, Callable[[], str | None] | None]) -> str:
    name, argv, valid, check = case
    code, err = run_command(argv)
    DETAILS[name] = f"exit {code}: {' | '.join(err.strip().splitlines()[-3:])}"[:300]
    override = check() if check else None
    if override:
        return override
    if code == "timeout":
        return "slow" if valid else "wrong"
    if "Traceback" in err:
        return "traceback"
    if code == 2:
        return "traceback" if valid else ("clean" if one_clean_line(err) else "traceback")
    return "ok" if valid and code in (0, 1) else "wrong"


def study_cases(folder: Path) -> list[tuple[str, Callable[[], str]]]:
    """Study runs and resumes on a tiny world whose goals include awkward names."""
    world = str(write_tiny_world(folder / "sw", extra_goals={"Polar bear": 4, "Polar_bear": 5, "../../x": 6}))
    base = ["study", "--world", world, "--perception", "geometric", "--trials", "1", "--workers", "2"]

    def csv_rows(out: Path) -> list[str]:
        return (out / "trials.csv").read_text().strip().splitlines()[1:] if (out / "trials.csv").exists() else []

    def fresh(name: str, goals: list[str]) -> tuple[Path, int | str, str]:
        out = folder / name
        code, err = run_command([*base, "--goals", *goals, "--out", str(out)], timeout=600)
        return out, code, err

    def verdict(code: int | str, err: str) -> str | None:
        if "Traceback" in err:
            return "traceback"
        if code == "timeout":
            return "slow"
        return None

    def first_run() -> str:
        out, code, err = fresh("s1", ["A"])
        return verdict(code, err) or ("ok" if code == 0 and len(csv_rows(out)) == 1 else "wrong")

    def other_perception() -> str:
        code, err = run_command([*base[:4], "camera", *base[5:], "--goals", "A", "--out", str(folder / "s1")],
                                timeout=600)
        if verdict(code, err):
            return verdict(code, err)  # type: ignore[return-value]
        return "clean" if code == 2 and one_clean_line(err) else "wrong"  # reusing geometric trials is wrong

    def duplicate_goals() -> str:
        out, code, err = fresh("s2", ["A", "A"])
        if verdict(code, err):
            return verdict(code, err)  # type: ignore[return-value]
        if code == 2 and one_clean_line(err):
            return "clean"
        return "ok" if len(csv_rows(out)) == 1 else "wrong"

    def corrupt_record() -> str:
        records = sorted((folder / "s1" / "trials").glob("*.json"))
        if not records:
            return "wrong"
        records[0].write_text('{"goal": "A", "se')
        code, err = run_command([*base, "--goals", "A", "--out", str(folder / "s1")], timeout=600)
        return verdict(code, err) or ("ok" if code == 0 and len(csv_rows(folder / "s1")) == 1 else "wrong")

    def truncated_csv() -> str:
        (folder / "s1" / "trials.csv").write_text("goal,se")
        code, err = run_command([*base, "--goals", "A", "--out", str(folder / "s1")], timeout=600)
        return verdict(code, err) or ("ok" if code == 0 and len(csv_rows(folder / "s1")) == 1 else "wrong")

    def similar_names() -> str:
        out, code, err = fresh("s3", ["Polar bear", "Polar_bear"])
        if verdict(code, err):
            return verdict(code, err)  # type: ignore[return-value]
        files = list((out / "trials").glob("*.json"))
        rows = csv_rows(out)
        goals = {row.split(",")[0] for row in rows}
        return "ok" if code == 0 and len(files) == 2 and goals == {"Polar bear", "Polar_bear"} else "wrong"

    def escaping_name() -> str:
        out, code, err = fresh("s4/deeper/out", ["../../x"])
        if verdict(code, err):
            return verdict(code, err)  # type: ignore[return-value]
        outside = [p for p in (folder / "s4").rglob("*") if out not in p.parents and p != out and p.is_file()]
        return "wrong" if outside else ("ok" if code == 0 else "wrong")

    def extend_trials() -> str:
        code, err = run_command([*base[:-4], "--trials", "2", "--workers", "2", "--goals", "A", "--out",
                                 str(folder / "s1")], timeout=600)
        return verdict(code, err) or ("ok" if code == 0 and len(csv_rows(folder / "s1")) == 2 else "wrong")

    return [("first run", first_run), ("resume with another --perception", other_perception),
            ("--goals A A", duplicate_goals), ("corrupt trial record", corrupt_record),
            ("truncated trials.csv", truncated_csv), ("'Polar bear' and 'Polar_bear'", similar_names),
            ("goal '../../x'", escaping_name), ("resume with more trials", extend_trials)]


# -- the campaign -------------------------------------------------------------------

def campaign(surfaces: list[str], scale: float, seed: int) -> dict[str, Any]:
    errors = project_errors()
    def rng(surface: str) -> random.Random:  # one stream per surface: a surface alone draws the same inputs
        return random.Random(f"{seed}-{surface}")
    results: dict[str, Counter] = {}
    examples: dict[str, dict[str, list[str]]] = {}

    def record(surface: str, outcome: str, label: str) -> None:
        results.setdefault(surface, Counter())[outcome] += 1
        bucket = examples.setdefault(surface, {}).setdefault(outcome, [])
        if outcome not in ("ok", "clean") and len(bucket) < 8:
            bucket.append(label[:400])

    def guarded(surface: str, fn: Callable[[], str], label: str) -> None:
        began = time.process_time()
        try:
            with time_limit(LIMIT_S):
                outcome = fn()
        except Timeout:
            outcome = "slow"
        except Exception as exc:  # noqa: BLE001  # a crash of the harness itself: count it as a traceback
            outcome, label = "traceback", f"{label} (harness: {type(exc).__name__}: {exc})"
        if outcome in ("ok", "clean") and time.process_time() - began > LIMIT_S:
            outcome = "slow"
        record(surface, outcome, label)

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        if "cue" in surfaces:
            for case in cue_inputs(rng('cue'), int(600 * scale) + 8):
                guarded("cue text", lambda c=case: run_cue(c, errors), repr(case)[:160])
        if "scenario" in surfaces:
            for case in scenario_inputs(rng('scenario'), int(400 * scale) + 23):
                guarded("scenario", lambda c=case: run_scenario(c, folder), repr(case)[:160])
            for _ in range(3):
                record("scenario", disk_full("imagine", folder), "imagine --out on a full disk")
        if "model" in surfaces:
            for case in model_inputs(rng('model'), int(400 * scale) + 7):
                guarded("saved model", lambda c=case: run_model(c, folder, errors), repr(case)[:160])
            for _ in range(3):
                record("saved model", disk_full("model", folder), "save() on a full disk")
        if "world" in surfaces:
            for case in world_inputs(rng('world'), int(300 * scale) + 27):
                guarded("world folder", lambda c=case: run_world(c, folder, errors), case[0])
        if "arguments" in surfaces:
            cases = argument_inputs(folder / "args")
            with ThreadPoolExecutor(2) as pool:
                for case, outcome in zip(cases, pool.map(run_argument, cases)):
                    label = case[0] if outcome in ("ok", "clean") else f"{case[0]} ({DETAILS.get(case[0], '')})"
                    record("arguments", outcome, label)
        if "study" in surfaces:
            (folder / "study").mkdir()
            for name, fn in study_cases(folder / "study"):
                try:
                    outcome = fn()
                except Exception as exc:  # noqa: BLE001
                    outcome, name = "traceback", f"{name} (harness: {exc})"
                record("study resume", outcome, name)
            record("study resume", disk_full("csv", folder), "trials.csv on a full disk")
    return {"counts": {s: dict(c) for s, c in results.items()}, "examples": examples}


def table(counts: dict[str, dict[str, int]]) -> str:
    lines = ["| surface | inputs | ok | clean errors | tracebacks | silent wrong | data lost | slow |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    total: Counter = Counter()
    for surface, c in counts.items():
        total.update(c)
        lines.append(f"| {surface} | {sum(c.values())} | " + " | ".join(str(c.get(o, 0)) for o in OUTCOMES) + " |")
    lines.append(f"| **all** | {sum(total.values())} | " + " | ".join(str(total.get(o, 0)) for o in OUTCOMES) + " |")
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--surfaces", nargs="+", default=["cue", "scenario", "model", "world", "arguments", "study"],
                        choices=["cue", "scenario", "model", "world", "arguments", "study"])
    parser.add_argument("--quick", action="store_true", help="a tenth of the random inputs")
    parser.add_argument("--seed", type=int, default=9)
    parser.add_argument("--json", type=Path, help="also write the counts and failing examples here")
    args = parser.parse_args()
    os.environ.setdefault("MPLBACKEND", "Agg")
    logging.disable(logging.WARNING)  # springs left out of clauses with no context are expected here
    began = time.perf_counter()
    result = campaign(args.surfaces, 0.1 if args.quick else 1.0, args.seed)
    print(table(result["counts"]))
    print(f"\n{time.perf_counter() - began:.0f} s", file=sys.stderr)
    for surface, outcomes in result["examples"].items():
        for outcome, labels in outcomes.items():
            for label in labels:
                print(f"  {surface} / {outcome}: {label}", file=sys.stderr)
    if args.json:
        args.json.write_text(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
