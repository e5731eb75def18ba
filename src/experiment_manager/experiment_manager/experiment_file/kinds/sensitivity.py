"""sensitivity: the experiments it names (`of`) again in scenarios of the uncertain inputs
(scenarios.py), and how far each verdict moves (analysis/sensitivity.py)."""

from dataclasses import replace
from typing import Any, ClassVar

from pick_common.errors import InvalidArgument

from .. import experiment_keys, schema
from .. import scenarios as scenario_inputs
from ..drop_test import drop_test_height
from ..model import Experiment, Input, OneContainerExperiment, SENSITIVITY, SensitivityExperiment
from .base import ExperimentKind, kind_of
from .context import Context


class Sensitivity(ExperimentKind):
    """Its repeats are experiments of their own (read before it); it has no iterations."""

    name: ClassVar[str] = SENSITIVITY
    keys: ClassVar[type] = experiment_keys.SensitivityKeys
    record: ClassVar[type] = SensitivityExperiment
    repeats_others: ClassVar[bool] = True

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        return read(e, where, c)

    def groups(self, exp: Experiment) -> list[int]:
        return []

    def scenes(self, file, exp: Experiment, summary: dict) -> list:
        return []


def _on_tray(exp: Experiment) -> bool:
    """Whether an experiment runs on the file's tray (no bin of its own or of another's)."""
    return isinstance(exp, OneContainerExperiment) and exp.bin is None and not exp.bin_from


def read(e: experiment_keys.SensitivityKeys, where: str, c: Context) -> list[Experiment]:
    """A sensitivity experiment and, before it, its repeats of the experiments it names, one
    per scenario (scenarios.py); a repeat takes its bin or range from the same scenario's
    repeat of its source when that is repeated too, else from the source itself."""
    for i, exp_id in enumerate(e.of):
        if c.earlier.get(exp_id) is None or kind_of(c.earlier[exp_id]).repeats_others:
            raise InvalidArgument(f'{where}.of[{i}]', exp_id, 'names no earlier experiment '
                                  '(of a type other than sensitivity)')
    if len(set(e.of)) != len(e.of):
        raise InvalidArgument(f'{where}.of', list(e.of), 'names an experiment twice')
    for i, exp_id in enumerate(e.of):
        if c.earlier[exp_id].gripper or c.earlier[exp_id].station:
            raise InvalidArgument(f'{where}.of[{i}]', exp_id, 'runs with a gripper of the '
                                  "file's grippers or a regrasp station; a sensitivity varies "
                                  "the file's own cell")
    inputs = []
    on_tray = [x for x in e.of if _on_tray(c.earlier[x])]
    for name, r in e.inputs.items():
        at = f'{where}.inputs.{name}'
        moved = name.removeprefix('part.')
        if name.startswith('part.') and moved in schema.MOVED_KEYS:
            raise InvalidArgument(at, name, f'has moved: vary materials.part_on_surface.{moved} '
                                  f'(the part on the bin or tray) or materials.part_on_part.'
                                  f'{moved} (on another part)')
        if name not in scenario_inputs.INPUTS:
            raise InvalidArgument(at, name, 'is not an input a sensitivity experiment varies ('
                                  + ', '.join(scenario_inputs.INPUTS) + ')')
        sweeps = [x for x in e.of if kind_of(c.earlier[x]).own_grippers]
        if name.startswith('gripper.') and sweeps:
            raise InvalidArgument(at, name, f'cannot reach the gripper_sweep {sweeps[0]}, whose '
                                  'grippers are its own: vary the gripper there, or leave it '
                                  'out of `of`')
        low = scenario_inputs.check_input(name, r.low, f'{at}.low')
        high = scenario_inputs.check_input(name, r.high, f'{at}.high')
        if name.startswith('tray.') and not on_tray:
            raise InvalidArgument(at, name, 'changes the tray, and none of the experiments of '
                                  '`of` runs on it (a table_sweep, a feeder_emptying, or a '
                                  'gripper_sweep with no bin)')
        if name == scenario_inputs.DROP_HEIGHT:
            base = drop_test_height(e.of, at, c.earlier)
        else:
            base = scenario_inputs.base_value(name, c.setup, c.geometry.mass, c.tray, at)
        inputs.append(Input(name, round(base, 9), low, high, r.source.strip()))
    inputs = tuple(inputs)
    repeats = (2 * len(inputs) + e.joint + (e.grid ** len(inputs) if e.grid else 0)) * len(e.of)
    if repeats > scenario_inputs.MAX_REPEATS:
        raise InvalidArgument(f'{where}.inputs', repeats, f'scenarios x experiments repeated '
                              f'is over the limit of {scenario_inputs.MAX_REPEATS} (2 '
                              'scenarios per input, plus joint, plus grid ** inputs, times the '
                              'experiments of `of`)')
    found = scenario_inputs.scenarios(inputs, e.joint, c.setup, c.moves, c.seed, e.id, where,
                                      e.grid, c.tray)
    repeats = []
    for scenario, setup, moves in found:
        for exp_id in e.of:
            source = c.earlier[exp_id]
            renamed = {key: f'{value}@{scenario.name}' if value in e.of else value
                       for key, value in source.taken_from.items()}
            if (height := scenario_inputs.drop_height(scenario)) is not None:
                renamed['bin'] = replace(source.bin, drop_height=height)
            elif _on_tray(source) and (tray := scenario_inputs.tray_of(scenario, c.tray)):
                renamed['bin'] = tray      # its one container (base.scene_container)
            repeats.append(replace(source, id=f'{exp_id}@{scenario.name}',
                                   iterations=min(source.iterations, e.iterations),
                                   scenario=scenario, setup=setup, moves=moves, **renamed))
    return repeats + [SensitivityExperiment(id=e.id, iterations=e.iterations, of=tuple(e.of),
                                            inputs=inputs, scenarios=tuple(s for s, _, _ in found),
                                            grid=e.grid)]
