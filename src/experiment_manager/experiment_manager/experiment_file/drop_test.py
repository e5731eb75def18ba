"""A drop_test experiment as the file gives it: the plate its parts are dropped on and the
measured counts, each named by an aspect of the part."""

from typing import Any

import numpy as np
from pick_common.containers import check_container, ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts.aspects import part_aspects
from pick_common.parts.geometry import PartGeometry

from . import schema
from .errors import checked
from .model import DROP_PLATE, MM


def drop_test(e: schema.DropTestKeys, where: str, geometry: PartGeometry, bin_wall: float
              ) -> dict[str, Any]:
    """A drop test's plate (a bin DROP_PLATE part radii wide, its walls only there to keep a
    bouncing part, parts arriving from height_mm) and its measured counts, each aspect name
    one of the part's; the Experiment's fields."""
    width = DROP_PLATE * (geometry.radius + float(np.linalg.norm(geometry.center)))
    plate = ContainerSpec(inner_size=(width, width, 0.02), wall_thickness=bin_wall,
                          drop_height=MM * e.height_mm)
    checked(check_container, plate, f'{where}.height_mm')
    if e.measured:
        names = [a.name for a in part_aspects(geometry)]
        for name in e.measured:
            if name not in names:
                raise InvalidArgument(f'{where}.measured.{name}', e.measured[name],
                                      f'is not an aspect of the part (its aspects: '
                                      f'{", ".join(names)})')
    return {'parts': 1, 'bin': plate, 'measured': tuple(e.measured.items())}
