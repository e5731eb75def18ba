"""The values of an experiment file as pydantic types: numbers, whole numbers, strings with
their choices, vectors and ids, each checked by the cores' own rules
(`pick_common.errors.check_number`, `check_int`), so that a range is written once and its
message reads the same wherever it is broken. A broken rule is a pydantic error of type RULE
whose context holds the rule, the value as the message shows it and what follows the key's
path (`[2]`): `errors.errors_of` names the key.
"""

from collections.abc import Callable, Mapping
from functools import partial
from typing import Annotated, Any

from pick_common.errors import check_int, check_number, InvalidArgument
from pydantic import BeforeValidator
from pydantic_core import PydanticCustomError

from .model import ID_CHARS

RULE = 'pick_rule'      # the error type of a rule broken (its message is the rule)


def short(value: Any) -> Any:
    """A value as an error message shows it: itself, or its repr cut at 60 characters."""
    text = repr(value)
    return value if len(text) < 60 else text[:57] + '...'


def fail(rule: str, value: Any, at: str = '') -> None:
    """Refuse a value: `rule` is the message, `at` what follows the key's path ('[2]')."""
    raise PydanticCustomError(RULE, '{rule}', {'rule': rule, 'value': value, 'at': at})


def _is_number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, int | float)


def number(value: Any, low: float | None, high: float | None, low_open: bool,
            at: str = '') -> float:
    if not _is_number(value):
        fail('is not a number', short(value), at)
    try:
        return check_number('', value, low=low, high=high, low_open=low_open)
    except InvalidArgument as exc:
        fail(exc.rule, exc.value, at)


def integer(value: Any, low: int, high: int) -> int:
    try:
        return check_int('', value, low=low, high=high)
    except InvalidArgument as exc:
        fail(exc.rule, exc.value)


def _text(value: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str):
        fail('is not a string', short(value))
    if choices and value not in choices:
        fail(f'must be one of {", ".join(choices)}', value)
    return value


def vector(value: Any, length: int, low: float | None, high: float | None,
            low_open: bool) -> tuple[float, ...]:
    if not isinstance(value, list | tuple) or len(value) != length:
        fail(f'must be a list of {length} numbers', short(value))
    return tuple(number(v, low, high, low_open, f'[{i}]') for i, v in enumerate(value))


def _identifier(value: Any) -> str:
    _text(value, ())
    if not value or len(value) > 64 or not set(value) <= ID_CHARS:
        fail('must be 1..64 letters, digits, _ or -', value)
    return value


def Number(low: float | None = None, high: float | None = None,  # noqa: N802 (a type)
           low_open: bool = False) -> Any:
    """A number (not a bool), finite, within [low, high] (low excluded when low_open)."""
    return Annotated[float, BeforeValidator(partial(number, low=low, high=high,
                                                    low_open=low_open))]


def Int(low: int, high: int) -> Any:  # noqa: N802 (a type)
    """A whole number within [low, high]."""
    return Annotated[int, BeforeValidator(partial(integer, low=low, high=high))]


def Text(*choices: str) -> Any:  # noqa: N802 (a type)
    """A string, one of `choices` when they are given."""
    return Annotated[str, BeforeValidator(partial(_text, choices=choices))]


def Vector(length: int, low: float | None = None, high: float | None = None,  # noqa: N802
           low_open: bool = False) -> Any:
    """A list of `length` numbers, each checked as a Number."""
    return Annotated[tuple[float, ...], BeforeValidator(partial(
        vector, length=length, low=low, high=high, low_open=low_open))]


Identifier = Annotated[str, BeforeValidator(_identifier)]
PositiveSize = Vector(3, low=0.0, low_open=True)          # a box [x, y, z], mm


def list_of(value: Any, low: int, high: int, what: str) -> list:
    if not isinstance(value, list) or not low <= len(value) <= high:
        fail(f'must be a list of {what}', short(value))
    return value


def grasp_list(value: Any, handler: Callable[[Any], Any]) -> list | str | None:
    """part.grasps: 'auto' as it is, else a non-empty list read by `handler`."""
    if value == 'auto':
        return value
    if value is not None and (not isinstance(value, list) or not value):
        fail("must be a non-empty list of grasps, or 'auto' (proposed from the part's "
             'geometry)', short(value))
    return handler(value)


def mapping(value: Any) -> Any:
    if not isinstance(value, Mapping):
        fail('must be a mapping of keys', short(value))
    return value
