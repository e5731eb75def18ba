"""Exceptions of the world core and the checks that raise them.

Every value is checked here before it reaches PyBullet: PyBullet accepts NaN silently and its
state becomes NaN. The node turns these exceptions into an error code and a message.
"""

from collections.abc import Iterable, Sequence
import math
import os


class WorldError(Exception):
    """Base class of the errors the world core raises on purpose."""


class InvalidArgument(WorldError):
    """A value is out of range, not finite, or inconsistent with another.

    The message names the field, the value and the rule it broke.
    """

    def __init__(self, field: str, value: object, rule: str) -> None:
        self.field = field
        self.value = value
        self.rule = rule
        super().__init__(f'{field}: {value!r} {rule}')


class UnknownInstance(WorldError):
    """An instance id that the scene does not have."""


class UnknownPart(WorldError):
    """A part id or a part model name that does not exist."""


class MeshError(InvalidArgument):
    """A user mesh that is missing, empty or degenerate."""


class PhysicsFault(WorldError):
    """The physics state became invalid (NaN or inf poses)."""


def check_number(field: str, value: float, *, low: float | None = None,
                 high: float | None = None, low_open: bool = False) -> float:
    """Return value as a float if it is finite and within [low, high] (low open if asked).

    Raises InvalidArgument naming field, the value and the limit otherwise.
    """
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InvalidArgument(field, value, 'is not a number') from None
    if not math.isfinite(number):
        raise InvalidArgument(field, value, 'must be finite')
    if low is not None and (number <= low if low_open else number < low):
        raise InvalidArgument(field, value, f'must be {">" if low_open else ">="} {low:g}')
    if high is not None and number > high:
        raise InvalidArgument(field, value, f'must be <= {high:g}')
    return number


def check_int(field: str, value: int, *, low: int, high: int) -> int:
    """Return value as an int if it is a whole number within [low, high]."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidArgument(field, value, 'is not an integer')
    if isinstance(value, float) and (not math.isfinite(value) or not value.is_integer()):
        raise InvalidArgument(field, value, 'is not an integer')
    number = int(value)
    if not low <= number <= high:
        raise InvalidArgument(field, value, f'must be within [{low}, {high}]')
    return number


def check_vector(field: str, values: Iterable[float], length: int, *,
                 low: float | None = None, high: float | None = None,
                 low_open: bool = False) -> tuple[float, ...]:
    """Check a fixed-length vector element by element; names the element that fails."""
    items = tuple(values)
    if len(items) != length:
        raise InvalidArgument(field, items, f'must have {length} elements')
    return tuple(check_number(f'{field}[{i}]', v, low=low, high=high, low_open=low_open)
                 for i, v in enumerate(items))


def check_inside(field: str, path: str, roots: Sequence[str], parameter: str) -> str:
    """The real path of `path` (relative to the working directory, symlinks and '..'
    resolved) if it lies inside one of `roots` (directories, resolved the same way), the
    places a node was given by its `parameter`. Raises InvalidArgument naming the field, the
    path and the places otherwise. Nothing is read, so a path outside gets the same answer
    whether it exists or not."""
    real = os.path.realpath(path)
    for root in roots:
        top = os.path.realpath(root)
        if os.path.commonpath([real, top]) == top:
            return real
    where = ', '.join(repr(r) for r in roots) if roots else 'none'
    raise InvalidArgument(field, path, f'is outside the directories this node may use '
                                       f'({parameter}: {where})')
