"""A drop_test experiment as the file gives it: the plate its parts are dropped on and the
measured counts, each named by an aspect of the part."""

from typing import Any

import numpy as np
from pick_common.containers import check_container, ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts.aspects import part_aspects
from pick_common.parts.geometry import PartGeometry

from . import experiment_keys
from .errors import checked
from .kinds.base import KINDS
from .model import DROP_PLATE, MM
from .scenarios import DROP_HEIGHT


def plate(geometry: PartGeometry, height: float, wall: float) -> ContainerSpec:
    """The plate a drop test drops `geometry`'s part onto from `height` (m): a bin DROP_PLATE
    part radii wide, its `wall` (m) walls only there to keep a bouncing part."""
    width = DROP_PLATE * (geometry.radius + float(np.linalg.norm(geometry.center)))
    return ContainerSpec(inner_size=(width, width, 0.02), wall_thickness=wall,
                         drop_height=height)


def drop_test(e: experiment_keys.DropTestKeys, where: str, geometry: PartGeometry, bin_wall: float
              ) -> dict[str, Any]:
    """A drop test's plate (`plate`, parts arriving from height_mm) and its measured counts,
    each aspect name one of the part's; the Experiment's fields."""
    plate_ = checked(check_container, plate(geometry, MM * e.height_mm, bin_wall),
                     f'{where}.height_mm')
    if e.measured:
        names = [a.name for a in part_aspects(geometry)]
        for name in e.measured:
            if name not in names:
                raise InvalidArgument(f'{where}.measured.{name}', e.measured[name],
                                      f'is not an aspect of the part (its aspects: '
                                      f'{", ".join(names)})')
    return {'parts': 1, 'bin': plate_, 'measured': tuple(e.measured.items())}


def drop_test_height(of: tuple[str, ...], where: str, earlier: dict) -> float:
    """The drop height, mm, of the experiments `of` names: all drop tests, of one height."""
    heights = set()
    for exp_id in of:
        source = earlier[exp_id]
        if not KINDS[source.type].names_aspects:
            raise InvalidArgument(where, DROP_HEIGHT, "varies a drop test's "
                                  f'height; {exp_id} is a {source.type}: name drop tests only')
        heights.add(round(source.bin.drop_height / MM, 9))
    if len(heights) > 1:
        raise InvalidArgument(where, DROP_HEIGHT, 'varies one height; the '
                              'drop tests named drop from ' + ', '.join(
                                  f'{h:g}' for h in sorted(heights)) + ' mm')
    return heights.pop()
