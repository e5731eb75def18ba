"""What an experiment's entry is read against (`Context`), and the checks the kinds share:
a bin in mm, an earlier experiment named by id, an experiment's `bin`."""

from typing import Any

from pick_common.containers import check_container, check_fits, ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import PartGeometry
from pick_common.specs import Vibration
from pick_validity.config import Setup

from ..errors import checked as checked_as
from ..model import Experiment, MM


class Context:
    """What an experiment's checks relate to: the part's geometry, the tray, the bins' wall
    and size limit, the setup (part, gripper, grasps) and table moves, the file's seed, and
    the experiments read before it."""

    def __init__(self, geometry: PartGeometry, tray: ContainerSpec, bin_wall: float,
                 bin_drop: float, max_dimension: float, setup: Setup,
                 moves: tuple[Vibration, ...], seed: int) -> None:
        self.geometry, self.tray, self.bin_wall = geometry, tray, bin_wall
        self.bin_drop = bin_drop
        self.max_dimension, self.setup, self.moves, self.seed = max_dimension, setup, moves, seed
        self.gripper, self.grasps = setup.gripper, setup.grasps
        self.earlier: dict[str, Experiment] = {}
        self.named: dict[str, Setup] = {}           # the file's `grippers`


def bin_spec(size_mm: tuple[float, ...], where: str, c: Context) -> ContainerSpec:
    size = tuple(MM * s for s in size_mm)
    for i, s in enumerate(size):
        if s > c.max_dimension + 1e-12:
            raise InvalidArgument(f'{where}[{i}]', round(s / MM, 6),
                                  f'mm is over the size limit requirements.max_dimension_mm '
                                  f'= {c.max_dimension / MM:g}')
    spec = ContainerSpec(inner_size=size, wall_thickness=c.bin_wall, drop_height=c.bin_drop)
    checked_as(check_container, spec, where)
    return spec


def earlier(where: str, exp_id: str, c: Context, kind: str, alternative: str) -> Experiment:
    """The earlier experiment of type `kind` named by id at `where`."""
    source = c.earlier.get(exp_id)
    if source is None or source.type != kind:
        raise InvalidArgument(where, exp_id, f'names no earlier {kind} experiment (give its '
                              f'id, or {alternative})')
    return source


def bin_or_source(value: Any, parts: int, where: str, c: Context) -> dict:
    """An experiment's `bin`: a bin in mm ({'bin': spec}) or the id of an earlier bin_static
    experiment whose best bin is used ({'bin_from': id}); {} when there is none. `parts` must
    fit in it (in every bin of the source)."""
    volume = c.geometry.volume
    if value is None:
        return {}
    if isinstance(value, str):
        source = earlier(f'{where}.bin', value, c, 'bin_static', 'a bin [x, y, z] in mm')
        for i, b in enumerate(source.bins):
            check_fits(f'{where}.parts ({value}.bins_mm[{i}])', parts, volume, b)
        return {'bin_from': value}
    spec = bin_spec(value, f'{where}.bin', c)
    check_fits(f'{where}.parts', parts, volume, spec)
    return {'bin': spec}
