"""Every pick_msgs type survives a CDR round trip, and every float field states its unit."""

import importlib
import pathlib
import re

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rosidl_parser.definition import (
    AbstractSequence,
    AbstractString,
    Array,
    BasicType,
    NamespacedType,
)

SOURCE = pathlib.Path(__file__).resolve().parents[1] / 'src' / 'pick_msgs_py'
KINDS = {'msg': ('',), 'srv': ('Request', 'Response'), 'action': ('Goal', 'Result', 'Feedback')}


def _types():
    for kind, parts in KINDS.items():
        module = importlib.import_module(f'pick_msgs.{kind}')
        for path in sorted((SOURCE / kind).glob(f'*.{kind}')):
            outer = getattr(module, path.stem)
            for part in parts:
                yield pytest.param(getattr(outer, part) if part else outer,
                                   id=f'{path.stem}{"." + part if part else ""}')


def _value(slot, rng: np.random.Generator, depth: int):
    if isinstance(slot, BasicType):
        name = slot.typename
        if name == 'boolean':
            return True
        if name in ('float', 'double'):
            return float(rng.uniform(-1e3, 1e3)) if name == 'double' else 0.5
        if name == 'octet':
            return b'\x07'
        bits = int(re.sub(r'\D', '', name) or 8)
        high = 2 ** (bits - 1) - 1 if name.startswith('int') else 2 ** bits - 1
        return int(rng.integers(0, min(high, 2**62), endpoint=True))
    if isinstance(slot, AbstractString):
        return f'text {depth} {int(rng.integers(1000))}'
    if isinstance(slot, NamespacedType):
        module = importlib.import_module('.'.join(slot.namespaces))
        return _filled(getattr(module, slot.name), rng, depth + 1)
    if isinstance(slot, Array):
        return [_value(slot.value_type, rng, depth) for _ in range(slot.size)]
    if isinstance(slot, AbstractSequence):
        return [_value(slot.value_type, rng, depth) for _ in range(2 if depth < 3 else 1)]
    raise AssertionError(f'no filler for {slot}')


def _filled(msg_type, rng, depth=0):
    msg = msg_type()
    names = msg_type.get_fields_and_field_types()
    for name, slot in zip(names, msg_type.SLOT_TYPES, strict=True):
        setattr(msg, name, _value(slot, rng, depth))
    return msg


@pytest.mark.parametrize('msg_type', list(_types()))
def test_round_trip(msg_type):
    msg = _filled(msg_type, np.random.default_rng(7))
    assert msg != msg_type(), 'the filler must set something'
    data = serialize_message(msg)
    assert deserialize_message(data, msg_type) == msg


def test_every_interface_file_is_covered():
    files = sum(len(list((SOURCE / kind).glob(f'*.{kind}'))) for kind in KINDS)
    cmake = (SOURCE / 'CMakeLists.txt').read_text()
    listed = re.findall(r'"((?:msg|srv|action)/\w+\.\w+)"', cmake)
    assert len(listed) == files and len(list(_types())) >= files


UNIT = re.compile(r'#.*\b(m|s|rad|kg|Hz|Pa|1|m\^3|m/s\^2)\b')


def test_every_float_field_states_its_unit():
    missing = []
    for path in sorted(SOURCE.glob('*/*.*')):
        if path.suffix not in ('.msg', '.srv', '.action'):
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split('#')[0]
            if re.match(r'\s*float(32|64)(\[\])?\s+\w+\s*$', code) and not UNIT.search(line):
                missing.append(f'{path.name}:{number}: {line.strip()}')
    assert not missing, 'float fields without a unit:\n' + '\n'.join(missing)
