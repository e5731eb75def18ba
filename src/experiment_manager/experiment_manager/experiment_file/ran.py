"""What deciding a run reads of the file it ran with (`model.Ran`), kept in the run's
resolved.json under `records` and read back from it, so that `decide` reads no experiment file
again and builds no part.

The records are kept as the run held them, in SI units and exact (a float as JSON writes it
reads back as the same float), so that a run decided again from them decides as it did: the
requirements and the cell's times, the aspects (each with its faces' normals), and each
experiment's record with its type, its fields by name, a container as its fields, a
gripper_sweep variant's gripper as its kind and fields and its grasps as the file would write
them. An experiment's `setup` and `moves` (what a named gripper or a sensitivity scenario
makes of the part, for the physics) are not kept: deciding reads none of them. Pure: no rclpy,
no simulator.
"""

from dataclasses import fields
from typing import Any

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.aspects import Aspect
from pick_validity.grippers import KINDS as GRIPPER_KINDS

from .kinds import KINDS
from .model import Cell, Experiment, GripperVariant, Input, Ran, Requirements, Scenario
from .part import GRASP_KEYS

BUILT = ('setup', 'moves')      # an experiment's fields made for the physics, not kept


def plain(ran: Ran) -> dict:
    """`ran`'s records as resolved.json keeps them (`records`)."""
    return {'requirements': _fields(ran.requirements), 'cell': _fields(ran.cell),
            'aspects': [{**_fields(a), 'normals': np.asarray(a.normals).tolist()}
                        for a in ran.aspects],
            'experiments': [{'type': e.type, **{f.name: _plain(getattr(e, f.name))
                                                for f in fields(e) if f.name not in BUILT}}
                            for e in ran.experiments]}


def read(data: dict, run_id: str, seed: int) -> Ran:
    """The records `plain` kept, of the run `run_id` with `seed`. KeyError, TypeError or
    ValueError for records that are not `plain`'s."""
    return Ran(id=run_id, seed=seed, requirements=Requirements(**data['requirements']),
               cell=Cell(**data['cell']),
               aspects=tuple(Aspect(**{**a, 'normal': tuple(a['normal']),
                                       'normals': np.array(a['normals'], dtype=float),
                                       'axis': None if a['axis'] is None else tuple(a['axis'])})
                             for a in data['aspects']),
               experiments=tuple(_experiment(e) for e in data['experiments']))


def _fields(record) -> dict:
    return {f.name: _plain(getattr(record, f.name)) for f in fields(record)}


def _plain(value: Any) -> Any:
    if isinstance(value, GripperVariant):
        return {'gripper': {'type': value.gripper.kind, **value.gripper.values()},
                'grasp_set': value.grasp_set, 'grasps': [grasp_keys(g) for g in value.grasps]}
    if isinstance(value, (ContainerSpec, Input, Scenario)):
        return _fields(value)
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    return value


def grasp_keys(g) -> dict:
    """A grasp as the file writes it: its name and its keys in the file's units (6
    decimals)."""
    out = {'name': g.name}
    for f in fields(g):
        if f.name in GRASP_KEYS:
            key, factor = GRASP_KEYS[f.name]
            value = getattr(g, f.name)
            out[key] = ([round(v / factor, 6) for v in value] if isinstance(value, tuple)
                        else round(value / factor, 6))
    return out


def _tuples(value: Any) -> Any:
    """A JSON value with its lists as tuples, as the records hold them."""
    return tuple(_tuples(v) for v in value) if isinstance(value, list) else value


def _container(value: dict | None) -> ContainerSpec | None:
    return None if value is None else ContainerSpec(**{k: _tuples(v) for k, v in value.items()})


def _scenario(value: dict | None) -> Scenario | None:
    return None if value is None else Scenario(value['name'], _tuples(value['values']))


def _variant(value: dict) -> GripperVariant:
    """A gripper_sweep variant: its gripper of its kind, and its grasps as that kind's
    written grasps (what the file gives)."""
    values = dict(value['gripper'])
    gripper = GRIPPER_KINDS[values.pop('type')](**values)
    written = {f.name for f in fields(gripper.written)}
    grasps = tuple(gripper.written(name=g['name'], **{
        name: _tuples([v * factor for v in g[key]]) if isinstance(g[key], list)
        else g[key] * factor
        for name, (key, factor) in GRASP_KEYS.items() if name in written and key in g})
        for g in value['grasps'])
    return GripperVariant(gripper, value['grasp_set'], grasps)


# how an experiment record's field reads back, by its name (the rest: lists as tuples)
FIELDS = {
    'bins': lambda v: tuple(_container(x) for x in v),
    'bin': _container,
    'variants': lambda v: tuple(_variant(x) for x in v),
    'inputs': lambda v: tuple(Input(**x) for x in v),
    'scenarios': lambda v: tuple(_scenario(x) for x in v),
    'scenario': _scenario,
}


def _experiment(data: dict) -> Experiment:
    record = KINDS[data['type']].record
    return record(**{f.name: FIELDS.get(f.name, _tuples)(data[f.name]) for f in fields(record)
                     if f.name not in BUILT})
