"""pydantic's errors of an experiment file as the workspace's: an `InvalidArgument` per error,
naming the key by its path in the file (`experiments[1].bins_mm[0][2]`), the value and the
rule; an unknown key with the nearest known one and the keys known there; a required key
that is missing beside an unknown one close to it as one error, the typo. And a core's check
run under the file's key (`checked`).
"""

from collections.abc import Callable, Mapping
import difflib
import types
from typing import Annotated, Any, get_args, get_origin, Union

from pick_common.errors import InvalidArgument
from pydantic import BaseModel, ValidationError

from .values import RULE, short


def checked(check: Callable, value: Any, where: str) -> Any:
    """Run a core check, naming the field in the file that held the value (`where`) before
    the core's own."""
    try:
        return check(value)
    except InvalidArgument as exc:
        raise InvalidArgument(f'{where} ({exc.field})', exc.value, exc.rule) from None


def read(model: type[BaseModel], value: Any, where: str
         ) -> tuple[Any, list[InvalidArgument]]:
    """`value` read with `model` (None when it has errors) and its errors, their paths under
    `where`."""
    try:
        return model.model_validate(value), []
    except ValidationError as exc:
        return None, errors_of(exc, model, where)


def path(where: str, loc: tuple) -> str:
    """A key's path in the file: `experiments[1].bins_mm[0]` from ('bins_mm', 0) under
    `experiments[1]`."""
    out = where
    for item in loc:
        if isinstance(item, int):
            out += f'[{item}]'
        else:
            out = f'{out}.{item}' if out else str(item)
    return out


def _unwrap(annotation: Any) -> Any:
    """The model (or mapping or list) inside an annotation: Annotated, Optional and unions of
    a model with a value are looked through."""
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            annotation = get_args(annotation)[0]
        elif origin in (Union, types.UnionType):
            args = [a for a in get_args(annotation) if a is not type(None)]
            annotation = next((a for a in args if isinstance(a, type)
                               and issubclass(a, BaseModel)), args[0])
        else:
            return annotation


def _known_keys(model: type[BaseModel], loc: tuple) -> list[str]:
    """The keys of the mapping at `loc` (a path below `model`), sorted; [] when unknown."""
    here: Any = model
    for item in loc:
        if isinstance(here, type) and issubclass(here, BaseModel):
            if not isinstance(item, str) or item not in here.model_fields:
                return []
            here = _unwrap(here.model_fields[item].annotation)
        elif get_origin(here) in (list, tuple) and isinstance(item, int):
            here = _unwrap(get_args(here)[0])
        elif get_origin(here) is dict:
            here = _unwrap(get_args(here)[1])
        else:
            return []
    if isinstance(here, type) and issubclass(here, BaseModel):
        return sorted(here.model_fields)
    return []


def _nearest(key: str, candidates) -> str | None:
    """The candidate closest to `key`, when one is close enough to be what was meant."""
    match = difflib.get_close_matches(str(key), [str(c) for c in candidates], n=1, cutoff=0.6)
    return match[0] if match else None


def errors_of(exc: ValidationError, model: type[BaseModel], where: str) -> list[InvalidArgument]:
    """pydantic's errors of a value read with `model` at `where`, as InvalidArguments that name
    the key by its path, the value and the rule. A required key that is missing beside an
    unknown key close to it is one error: the typo."""
    errors = exc.errors(include_url=False)
    missing = {(e['loc'][:-1], e['loc'][-1]) for e in errors if e['type'] == 'missing'}
    typos: dict[tuple, str] = {}
    for e in errors:
        if e['type'] == 'extra_forbidden':
            parent, key = e['loc'][:-1], e['loc'][-1]
            near = _nearest(key, [k for p, k in missing if p == parent])
            if near is not None:
                typos[e['loc']] = near
    out = []
    for e in errors:
        loc, kind, value = e['loc'], e['type'], e.get('input')
        field = path(where, loc)
        if kind == 'missing':
            if (loc[:-1], loc[-1]) in {(t[:-1], near) for t, near in typos.items()}:
                continue                                # told as the typo beside it
            out.append(InvalidArgument(field, None, 'is required'))
        elif kind == 'extra_forbidden':
            shown = '{...}' if isinstance(value, Mapping) else short(value)
            if loc in typos:
                out.append(InvalidArgument(field, shown, f'is not a known key here (did you '
                                           f'mean {typos[loc]}? it is required)'))
                continue
            known = _known_keys(model, loc[:-1])
            near = _nearest(loc[-1], known)
            out.append(InvalidArgument(field, shown, 'is not a known key here'
                                       + (f' (did you mean {near}?)' if near else '')
                                       + (f' (known: {", ".join(known)})' if known else '')))
        elif kind == RULE:
            ctx = e['ctx']
            out.append(InvalidArgument(field + ctx['at'], ctx['value'], ctx['rule']))
        elif kind in ('model_type', 'model_attributes_type', 'dict_type'):
            out.append(InvalidArgument(field or 'file', short(value),
                                       'must be a mapping of keys'))
        else:                   # a rule of pydantic's own, in its words
            out.append(InvalidArgument(field or 'file', short(value), e['msg'].lower()))
    return out
