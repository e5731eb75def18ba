"""A sensitivity experiment's scenarios: the inputs nobody can measure before the hardware is
bought, varied one at a time and jointly, each scenario a setup and table moves for the
repeats of the experiments it names.

The inputs (`INPUTS`), in the file's units: each contact pair's friction, rolling and
spinning arms and restitution (materials.part_on_surface.*, materials.part_on_part.*), the
part's mass (part.mass_g), the gripper's dimensions (gripper.*), and the table moves'
amplitude, frequency and duration as factors on every move of the cycle (moves.*_scale: the
cycle may mix moves, so one number in Hz or s would not say which), the height drop tests
drop from (drop_test.height_mm: of a sensitivity whose experiments are all drop tests of one
height; a calibration fits it as the effective height of the user's drops), and the tray's
hopper and walls (tray.hopper_lip_mm, tray.hopper_rate, tray.hopper_speed_mm_s,
tray.wall_mm: the repeats of the experiments that run on the tray run on the tray they make,
tray_of). The design:
- one at a time: a scenario at each input's low and one at its high, the others at the file's
  values (`<input>_low`, `<input>_high`, dots as underscores);
- joint (`joint: K`): K scenarios of a Latin hypercube over all the inputs' ranges (McKay,
  Beckman and Conover, Technometrics 21(2), 1979): each input's range cut in K equal strata,
  one value drawn in each, the strata paired at random; seeded by the file's seed and the
  experiment's id (`joint_1` ... `joint_K`);
- grid (`grid: L`): every combination of each input at L levels evenly from its low to its
  high (`grid_1` ... in the order of itertools.product, the last input varying fastest): with
  two inputs, a map of the verdicts over them (the report draws it).
Every repeat runs on the seeds of the experiment it repeats (plan.iteration_seed takes the
repeated experiment's id): what differs between scenarios is the input, not the draw
(common random numbers).

Pure: no rclpy, no simulator.
"""

from dataclasses import replace
import itertools
import zlib

import numpy as np
from pick_common import containers
from pick_common.containers import check_container, ContainerSpec
from pick_common.errors import check_number, InvalidArgument
from pick_common.parts.materials import body_values
from pick_common.specs import check_vibration, Vibration
from pick_validity.config import Setup
from pick_validity.grippers import KINDS, not_its_key

from .errors import checked
from .model import G, Input, MM, Scenario

# name -> (section, attribute, the file unit in SI, low limit, high limit, low open)
INPUTS = {
    **{f'materials.{pair}.{key}': ('materials', f'{pair}.{attr}', unit, 0.0, high, False)
       for pair in ('part_on_surface', 'part_on_part')
       for key, attr, unit, high in (('lateral_friction', 'lateral_friction', 1.0, 10.0),
                                     ('rolling_friction_mm', 'rolling_friction', MM, 100.0),
                                     ('spinning_friction_mm', 'spinning_friction', MM, 100.0),
                                     ('restitution', 'restitution', 1.0, 1.0))},
    'part.mass_g': ('part', 'mass', G, 0.0, 10_000.0, True),
    # every gripper kind's keys, with their kind's limits (pick_validity.grippers: KEYS)
    **{f'gripper.{key.file_key}': ('gripper', key.field, key.factor, key.limit.low / key.factor,
                                   key.limit.high / key.factor, key.limit.low_open)
       for kind in KINDS.values() for key in kind.KEYS},
    'moves.amplitude_scale': ('moves', 'amplitude', 1.0, 0.0, None, True),
    'moves.frequency_scale': ('moves', 'frequency', 1.0, 0.0, None, True),
    'moves.duration_scale': ('moves', 'duration', 1.0, 0.0, None, True),
    'drop_test.height_mm': ('drop_test', 'height', MM, 0.0, 1000.0, False),
    # the tray's hopper and walls: the repeats that run on the tray run on the tray they make
    'tray.hopper_lip_mm': ('tray', 'drop_height', MM, 0.0, 1000.0, False),
    'tray.hopper_rate': ('tray', 'hopper_rate', 1.0, 0.1, 1000.0, False),
    'tray.hopper_speed_mm_s': ('tray', 'hopper_speed', MM, 0.0, 2000.0, True),
    'tray.wall_mm': ('tray', 'wall', MM, 5.0, 2000.0, False),
}
DROP_HEIGHT = 'drop_test.height_mm'     # the drop tests' height: of `of`'s drop tests only
MAX_REPEATS = 200    # scenarios x experiments repeated, per sensitivity experiment


def drop_height(scenario: Scenario) -> float | None:
    """The drop height a scenario sets for the drop tests it repeats, m (None: their own)."""
    value = dict(scenario.values).get(DROP_HEIGHT)
    return None if value is None else value * INPUTS[DROP_HEIGHT][2]


def tray_of(scenario: Scenario, tray: ContainerSpec) -> ContainerSpec | None:
    """The tray a scenario makes of the file's `tray` (None: it sets no tray input)."""
    values = {INPUTS[k][1]: v * INPUTS[k][2] for k, v in scenario.values
              if INPUTS[k][0] == 'tray'}
    if not values:
        return None
    x, y, z = tray.inner_size
    return replace(tray, inner_size=(x, y, values.pop('wall', z)), **values)


def _tray_value(attr: str, tray: ContainerSpec) -> float:
    """The tray's value of a tray input's attribute, SI."""
    if attr == 'wall':
        return tray.inner_size[2]
    if attr == 'drop_height':
        return containers.drop_height(tray)
    return dict(zip(('hopper_rate', 'hopper_speed'), containers.hopper(tray), strict=True))[attr]


def base_value(name: str, setup: Setup, mass: float, tray: ContainerSpec,
               where: str = '') -> float:
    """The file's value of input `name`, in the file's units (`mass`: the part's mass, kg,
    which the file may leave to the model; `tray`: the file's); InvalidArgument named `where`
    for a key of the other kind of gripper."""
    section, attr, unit = INPUTS[name][:3]
    if section == 'tray':
        return _tray_value(attr, tray) / unit
    if section == 'gripper' and attr not in setup.gripper.values():
        raise InvalidArgument(where or name, name,
                              not_its_key(name.split('.', 1)[1], setup.gripper))
    if section == 'moves':
        return 1.0
    if attr == 'mass':
        return mass / unit
    if section == 'materials':
        pair, attr = attr.split('.')
        return getattr(getattr(setup.part, pair), attr) / unit
    return getattr(getattr(setup, section), attr) / unit


def check_input(name: str, value: float, where: str) -> float:
    """An input's value within its key's limits (the schema's for the part's keys)."""
    low, high, low_open = INPUTS[name][3:]
    return check_number(where, value, low=low, high=high, low_open=low_open)


def apply(values: dict[str, float], setup: Setup, moves: tuple[Vibration, ...], where: str
          ) -> tuple[Setup, tuple[Vibration, ...]]:
    """The setup and moves with `values` (input name -> file units) set, each checked by the
    core's rules, named at `where`."""
    part, gripper, scale = {}, {}, {}
    pairs = {'part_on_surface': {}, 'part_on_part': {}}
    for name, value in values.items():
        section, attr, unit = INPUTS[name][:3]
        if section in ('drop_test', 'tray'):    # the repeats' containers (tray_of)
            continue
        if section == 'materials':
            pair, attr = attr.split('.')
            pairs[pair][attr] = value * unit
            continue
        {'part': part, 'gripper': gripper, 'moves': scale}[section][attr] = value * unit
    for pair, changed in pairs.items():
        if changed:
            part[pair] = replace(getattr(setup.part, pair), **changed)
    if any(pairs.values()):
        new_part = replace(setup.part, **part)
        checked(lambda p: body_values(p.part_on_surface, p.part_on_part), new_part, where)
    new_gripper = checked(lambda g: g.check(), setup.gripper.with_values(**gripper), where)
    new_moves = [checked(check_vibration, Vibration(
        tuple(a * scale.get('amplitude', 1.0) for a in m.amplitude),
        m.frequency * scale.get('frequency', 1.0), m.duration * scale.get('duration', 1.0),
        m.direction), f'{where} (moves[{i}])') for i, m in enumerate(moves)]
    return (replace(setup, part=replace(setup.part, **part), gripper=new_gripper),
            tuple(new_moves))


def latin_hypercube(inputs: tuple[Input, ...], k: int, seed: int, experiment_id: str
                    ) -> list[dict[str, float]]:
    """k points of a Latin hypercube over the inputs' [low, high] (module docstring)."""
    rng = np.random.default_rng([seed & 0xFFFFFFFF, seed >> 32,
                                 zlib.crc32(experiment_id.encode())])
    points = [{} for _ in range(k)]
    for x in inputs:
        strata = (rng.permutation(k) + rng.random(k)) / k
        for point, u in zip(points, strata, strict=True):
            point[x.name] = float(x.low + u * (x.high - x.low))
    return points


def grid_levels(x: Input, levels: int) -> list[float]:
    """`levels` values of `x` evenly from its low to its high."""
    return np.linspace(x.low, x.high, levels).tolist()


def grid(inputs: tuple[Input, ...], levels: int) -> list[dict[str, float]]:
    """Every combination of each input at `levels` values evenly from its low to its high
    (none for 0 levels)."""
    if not levels:
        return []
    axes = [[(x.name, v) for v in grid_levels(x, levels)] for x in inputs]
    return [dict(point) for point in itertools.product(*axes)]


def point_key(inputs: tuple[Input, ...], values: dict[str, float]) -> tuple[float, ...]:
    """Every input's value in a scenario of `values` (the file's where not given), rounded as
    the file's values are: equal keys, the same inputs."""
    return tuple(round(float(values.get(x.name, x.base)), 9) for x in inputs)


def scenarios(inputs: tuple[Input, ...], joint: int, setup: Setup,
              moves: tuple[Vibration, ...], seed: int, experiment_id: str, where: str,
              levels: int = 0, tray: ContainerSpec | None = None
              ) -> tuple[tuple[Scenario, Setup, tuple[Vibration, ...]], ...]:
    """The scenarios of a sensitivity experiment (module docstring), each checked, with the
    setup and moves it makes (what its repeats run with). A point
    whose inputs are all the file's or an earlier scenario's is left out: on the same seeds it
    would give the same answers (an input's low at the file's value; a grid holds each input's
    ends with the others at the file's values when those are among its levels)."""
    design: list[tuple[str, dict[str, float]]] = []
    for x in inputs:
        stem = x.name.replace('.', '_')
        design += [(f'{stem}_low', {x.name: x.low}), (f'{stem}_high', {x.name: x.high})]
    design += [(f'joint_{i + 1}', point) for i, point in
               enumerate(latin_hypercube(inputs, joint, seed, experiment_id))]
    design += [(f'grid_{i + 1}', point) for i, point in enumerate(grid(inputs, levels))]
    seen = {point_key(inputs, {})}
    out = []
    for name, values in design:
        if (key := point_key(inputs, values)) in seen:
            continue
        seen.add(key)
        s, m = apply(values, setup, moves, f'{where}.inputs ({name})')
        scenario = Scenario(name, tuple(values.items()))
        out.append((scenario, s, m))
        if tray is not None:
            checked(check_container, tray_of(scenario, tray) or tray, f'{where}.inputs ({name})')
    return tuple(out)
