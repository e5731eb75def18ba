"""Hypothesis strategies for ROS 2 requests, built from the interface definitions themselves.

`values(type)` is any value of a field type (NaN, inf and huge numbers, integer limits, empty and
long strings, paths that leave a directory, empty and oversized sequences); `requests(template)`
is mostly a valid message with one to three fields, at any depth, replaced by such values (a
whole random message otherwise), so the checks behind the first field are reached too.
"""

from collections import Counter
import copy
import importlib
import math

from hypothesis import strategies as st
from rosidl_parser import definition as d

TRIED: dict[str, Counter] = {}   # endpoint -> answers per error code, for the test summary
MAX_SEQUENCE = 8          # elements of a random sequence
MAX_TEXT = 64             # characters of a random string
FLOATS = [math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, -1e-9, 1e-3, 1e9, 1e300, -1e300]
FLOAT32_MAX = 3.4028234663852886e38
TEXTS = ['', '.', '..', '../../../../etc/passwd', '/etc/passwd', '/proc/self/environ', '~',
         'mesh', 'radial_capacitor', 'x' * 5000, 'naïve ✓', ' ', '\n']
INTEGERS = {'int8': 8, 'int16': 16, 'int32': 32, 'int64': 64, 'uint8': -8, 'uint16': -16,
            'uint32': -32, 'uint64': -64, 'char': -8, 'octet': -8, 'short': 16,
            'unsigned short': -16, 'long': 32, 'unsigned long': -32, 'long long': 64,
            'unsigned long long': -64}


def _bounds(typename: str) -> tuple[int, int]:
    bits = INTEGERS[typename]
    return (0, 2 ** -bits - 1) if bits < 0 else (-2 ** (bits - 1), 2 ** (bits - 1) - 1)


def message_class(t: d.NamespacedType) -> type:
    return getattr(importlib.import_module('.'.join(t.namespaces)), t.name)


def fields(cls: type) -> list[tuple[str, d.AbstractType]]:
    return list(zip(cls.get_fields_and_field_types(), cls.SLOT_TYPES, strict=True))


def values(t: d.AbstractType) -> st.SearchStrategy:
    """Any value a field of type `t` can hold in rclpy."""
    if isinstance(t, d.BasicType):
        name = t.typename
        if name in ('float', 'double'):
            nasty = [x for x in FLOATS if name == 'double' or not math.isfinite(x)
                     or abs(x) <= FLOAT32_MAX]      # rclpy refuses finite float32 overflow
            return st.one_of(st.sampled_from(nasty),
                             st.floats(width=32 if name == 'float' else 64))
        if name == 'boolean':
            return st.booleans()
        low, high = _bounds(name)
        edges = [low, high, 0, 1, low + 1, high - 1]
        if name == 'octet':
            return st.integers(low, high).map(lambda i: bytes([i]))
        return st.one_of(st.sampled_from(edges), st.integers(low, high))
    if isinstance(t, d.AbstractString):
        return st.one_of(st.sampled_from(TEXTS), st.text(max_size=MAX_TEXT))
    if isinstance(t, d.NamespacedType):
        return messages(message_class(t))
    if isinstance(t, d.Array):
        return st.lists(values(t.value_type), min_size=t.size, max_size=t.size)
    if isinstance(t, d.AbstractSequence):
        size = t.maximum_size if isinstance(t, d.BoundedSequence) else MAX_SEQUENCE
        return st.lists(values(t.value_type), max_size=size)
    raise TypeError(f'no strategy for {t!r}')


def messages(cls: type) -> st.SearchStrategy:
    """A message of `cls` with every field random."""
    return st.fixed_dictionaries({name: st.deferred(lambda t=t: values(t))
                                  for name, t in fields(cls)}).map(lambda kw: cls(**kw))


def _spots(msg, path: tuple = ()) -> list[tuple[tuple, d.AbstractType]]:
    """Every field of `msg` at any depth, with the elements of sequences of messages."""
    out = []
    for name, t in fields(type(msg)):
        here = (*path, name)
        out.append((here, t))
        value = getattr(msg, name)
        if isinstance(t, d.NamespacedType):
            out += _spots(value, here)
        elif isinstance(t, d.AbstractNestedType) and isinstance(t.value_type, d.NamespacedType):
            for i, item in enumerate(value):
                out += _spots(item, (*here, i))
    return out


def _set(msg, path: tuple, value) -> None:
    *head, last = path
    for step in head:
        msg = msg[step] if isinstance(step, int) else getattr(msg, step)
    setattr(msg, last, value)


@st.composite
def requests(draw, template) -> object:
    """Mostly `template` with one to three fields replaced by any value of their type; one
    time in five a whole random message."""
    if draw(st.integers(0, 4)) == 0:
        return draw(messages(type(template)))
    msg = copy.deepcopy(template)
    for _ in range(draw(st.integers(1, 3))):
        path, t = draw(st.sampled_from(_spots(msg)))
        _set(msg, path, draw(values(t)))
    return msg


# ------------------------------------------------------------------------ YAML documents
LEAVES = st.one_of(st.none(), st.booleans(), st.integers(-2 ** 70, 2 ** 70), st.floats(),
                   st.sampled_from(TEXTS), st.text(max_size=16))
YAML_VALUES = st.recursive(LEAVES, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)),
    max_leaves=8)


def _places(doc, path: tuple = ()) -> list[tuple]:
    out = [path] if path else []
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) \
        if isinstance(doc, list) else ()
    for key, value in items:
        out += _places(value, (*path, key))
    return out


@st.composite
def documents(draw, template: dict) -> dict:
    """`template` (a YAML mapping) with one to three values replaced by any YAML value, deleted,
    or given an unknown sibling key."""
    doc = copy.deepcopy(template)
    for _ in range(draw(st.integers(1, 3))):
        places = _places(doc)
        if not places:
            break
        *head, last = draw(st.sampled_from(places))
        parent = doc
        for step in head:
            parent = parent[step]
        action = draw(st.sampled_from(['replace', 'replace', 'delete', 'add']))
        if action == 'delete' and isinstance(parent, dict):
            del parent[last]
        elif action == 'add' and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=8))] = draw(YAML_VALUES)
        else:
            parent[last] = draw(YAML_VALUES)
    return doc
