"""The project's errors and the checks that raise them.

Every mistake in an input (cue text, a scenario, a saved model, a world
folder, a command's arguments) raises a subclass of :class:`AbstractMapError`
whose message names the input and what was expected, on one line. The
command line prints that line and exits with code 2; anything else escaping is
a bug.

Numbers that enter the model are checked here: finite and within a stated
range, or refused with their name and value.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

COORDINATE_LIMIT_M = 1.0e6
"""|x|, |y| (m) of any pose, position or centre: 1,000 km, far beyond any building, and small
enough that every distance, spring force and squared length stays finite in float64."""

ANGLE_LIMIT = 1.0e6
"""|angle| (degrees or radians, as given) accepted before wrapping; larger values have lost their precision."""

VELOCITY_LIMIT_M_S = 1.0e6
"""|v| (m/s) of a saved place velocity."""

TAG_ID_LIMIT = 2**31
"""Tag ids are integers in [0, 2**31)."""

NAME_LIMIT = 200
"""Characters in a place name."""


class AbstractMapError(ValueError):
    """An input the project refuses: the message names the input and what was expected."""


class CueError(AbstractMapError):
    """Cue text that the grammar cannot turn into clauses, or clauses the model cannot take."""


class HierarchyError(AbstractMapError):
    """A hierarchy that is malformed: bad XML, a place with two parents, a cycle."""


class ScenarioError(AbstractMapError):
    """A scenario file that cannot be replayed."""


class ModelError(AbstractMapError):
    """An argument the model cannot take: a pose, a centre, a tag id, a place name."""


class ModelFileError(AbstractMapError):
    """A saved model that cannot be read."""


class UnknownPlaceError(ModelError, KeyError):
    """A place that no cue or hierarchy mentions."""

    def __str__(self) -> str:
        return str(self.args[0])


def one_line(text: str, limit: int = 400) -> str:
    """``text`` on one line, shortened to ``limit`` characters."""
    flat = " ".join(str(text).split())
    return flat if len(flat) <= limit else flat[: limit - 3] + "..."


def show(value: Any, limit: int = 60) -> str:
    """A short ``repr`` of an input value for an error message."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        return f"an integer of about {int(value.bit_length() * math.log10(2)) + 1} digits"
    try:
        text = repr(value)
    except (RecursionError, ValueError):  # a deeply nested container; an object whose repr fails
        return f"a {type(value).__name__}"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def number(where: str, value: Any, *, low: float = -math.inf, high: float = math.inf,
           error: type[AbstractMapError] = AbstractMapError) -> float:
    """``value`` as a float, if it is a real number (not a bool), finite and in [low, high]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise error(f"{where}: expected a number, got {show(value)}")
    try:
        result = float(value)
    except (OverflowError, ValueError):
        raise error(f"{where}: expected a finite number, got {show(value)}") from None
    if not math.isfinite(result):
        raise error(f"{where}: expected a finite number, got {show(value)}")
    if not low <= result <= high:
        raise error(f"{where}: expected a number in [{low:g}, {high:g}], got {show(value)}")
    return result


def coordinate(where: str, value: Any, error: type[AbstractMapError] = AbstractMapError) -> float:
    """A coordinate in metres, within +-:data:`COORDINATE_LIMIT_M`."""
    return number(where, value, low=-COORDINATE_LIMIT_M, high=COORDINATE_LIMIT_M, error=error)


def angle(where: str, value: Any, error: type[AbstractMapError] = AbstractMapError) -> float:
    """An angle (degrees or radians, as given), within +-:data:`ANGLE_LIMIT`."""
    return number(where, value, low=-ANGLE_LIMIT, high=ANGLE_LIMIT, error=error)


def integer(where: str, value: Any, *, low: int, high: int, error: type[AbstractMapError] = AbstractMapError) -> int:
    """``value`` if it is an int (not a bool) in [low, high)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise error(f"{where}: expected an integer, got {show(value)}")
    if not low <= value < high:
        raise error(f"{where}: expected an integer in [{low}, {high}), got {show(value)}")
    return int(value)


def tag_id(where: str, value: Any, error: type[AbstractMapError] = AbstractMapError) -> int:
    """A tag id: an integer in [0, :data:`TAG_ID_LIMIT`)."""
    return integer(where, value, low=0, high=TAG_ID_LIMIT, error=error)


def _sequence(where: str, values: Any, count: int, expected: str, error: type[AbstractMapError]) -> list[Any]:
    """``values`` as a list of ``count`` items, or ``error`` saying what was ``expected``."""
    try:
        items = list(values)
    except TypeError:
        raise error(f"{where}: expected {expected}, got {show(values)}") from None
    if len(items) != count:
        raise error(f"{where}: expected {expected}, got {show(values)}")
    return items


def point(where: str, values: Any, *, error: type[AbstractMapError] = AbstractMapError) -> tuple[float, float]:
    """(x m, y m) with finite coordinates in range."""
    x, y = _sequence(where, values, 2, "(x, y) in metres", error)
    return coordinate(f"{where} x", x, error), coordinate(f"{where} y", y, error)


def pose(where: str, values: Any, *, error: type[AbstractMapError] = AbstractMapError) -> tuple[float, float, float]:
    """(x m, y m, theta) with finite coordinates in range and a finite angle."""
    x, y, theta = _sequence(where, values, 3, "a pose of 3 numbers (x m, y m, theta)", error)
    return coordinate(f"{where} x", x, error), coordinate(f"{where} y", y, error), angle(f"{where} theta", theta, error)


def place_name(where: str, name: Any, *, error: type[AbstractMapError] = AbstractMapError) -> str:
    """A place name: text, not empty, at most :data:`NAME_LIMIT` characters, no control characters,
    not starting with '#' (the prefix of fixed points such as ``#start`` and ``#3``)."""
    if not isinstance(name, str):
        raise error(f"{where}: a place name must be text, got {show(name)}")
    if not name.strip():
        raise error(f"{where}: empty place name")
    if len(name) > NAME_LIMIT:
        raise error(f"{where}: place name of {len(name)} characters; at most {NAME_LIMIT}")
    if name != name.strip() or any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise error(f"{where}: place name {show(name)} has surrounding spaces or control characters")
    if name.startswith("#"):
        raise error(f"{where}: place name {show(name)} may not start with '#' (it names fixed points)")
    return name
