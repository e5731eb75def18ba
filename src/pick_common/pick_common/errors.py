"""The exceptions every core of the workspace raises on purpose, and the checks that raise them.

Every value is checked with these before it reaches PyBullet or FCL: PyBullet accepts NaN
silently and its state becomes NaN. A node turns these exceptions into an error code and a
message (`pick_common.conversions.error_code`, `pick_common.node_runner.answer_error`).

A `Limit` is the range of one setting, written once: the core's check enforces it and the
node's parameter descriptor states it (`pick_common.node_runner.declare`).
"""

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
import math
import os


class PickError(Exception):
    """Base class of the errors the cores raise on purpose (bad input, physics faults)."""


class CodedError(Exception):
    """A failed call to another node: `code` is the pick_msgs error code to answer with (the
    other node's own, or INTERNAL when it is missing or was lost, CANCELED when canceled)."""

    def __init__(self, code: int, message: str) -> None:
        self.code = code
        super().__init__(message)


class InvalidArgument(PickError):
    """A value is out of range, not finite, or inconsistent with another.

    The message names the field, the value and the rule it broke.
    """

    def __init__(self, field: str, value: object, rule: str) -> None:
        self.field = field
        self.value = value
        self.rule = rule
        super().__init__(f'{field}: {value!r} {rule}')


class DoesNotFit(InvalidArgument):
    """Parts that do not fit their container (containers.check_fits); `most` is the most of
    them that fit."""

    def __init__(self, field: str, value: object, rule: str, most: int) -> None:
        super().__init__(field, value, rule)
        self.most = most


class UnknownInstance(PickError):
    """An instance id that the scene does not have."""


class UnknownPart(PickError):
    """A part id or a part model name that does not exist."""


class MeshError(InvalidArgument):
    """A user mesh that is missing, empty or degenerate."""


class PhysicsFault(PickError):
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


@dataclass(frozen=True)
class Limit:
    """The range of one setting: [low, high] (low excluded when `low_open`), whole numbers when
    `integer`. `check` enforces it; a node's parameter descriptor states it."""

    low: float
    high: float
    integer: bool = False
    low_open: bool = False

    def check(self, field: str, value, *, low: float | None = None):
        """value as an int or a float if it lies within the limit; `low` raises the lower
        bound (included) for a rule that depends on another field. Raises InvalidArgument
        naming field, value and limit otherwise."""
        bound, low_open = self.low, self.low_open
        if low is not None and low > self.low:
            bound, low_open = low, False
        if self.integer:
            return check_int(field, value, low=int(bound), high=int(self.high))
        return check_number(field, value, low=bound, high=self.high, low_open=low_open)
