"""What every gripper kind is made of (the kinds: jaws.py, suction_cup.py; their union and
registry: the package's __init__): the table of its keys (`Key`), what every check of a setup
shares of it (`Grip`) and the methods every kind inherits (`Kind`).

Units: SI.
"""

from dataclasses import dataclass, fields, replace
from typing import ClassVar, TYPE_CHECKING

import numpy as np
from pick_common.errors import Limit

if TYPE_CHECKING:       # the collision stack is loaded where a kind builds shapes, not here
    from ..geometry import Shape
    from ..grasp_fit import GraspFit
    from ..suction import Holding, Seal

ASSUMED = 'assumed'
# The file's unit of a key: the suffix of its name there and its factor to SI.
UNITS = {'mm': ('_mm', 1e-3), 'kPa': ('_kpa', 1000.0), 'm/s^2': ('_m_s2', 1.0), '': ('', 1.0)}


@dataclass(frozen=True)
class Key:
    """One key of a gripper kind: `field` its dataclass field in SI units (the validity node's
    parameter gripper.<field>, the Jaws message's field), `unit` the experiment file's unit
    (its key is the field with the unit's suffix: body_diameter_mm), `limit` in SI, `text`
    what it is, `source` where its default comes from."""

    field: str
    unit: str
    limit: Limit
    text: str
    source: str = ASSUMED

    @property
    def file_key(self) -> str:
        return self.field + UNITS[self.unit][0]

    @property
    def factor(self) -> float:
        """The file's unit in SI."""
        return UNITS[self.unit][1]


@dataclass(frozen=True, eq=False)
class Grip:
    """What every check of one setup shares of its gripper: the wrist tilts it tries (T,),
    rad; per grasp, what the jaws close on (grasp_fit; a cup's: none), how far below the grasp
    point its fingertips reach, m, the axis of the round body it may turn about (zeros: fixed
    to the part), its shapes, and whether the check may use it (a cup's that seals and holds;
    every jaws' grasp); a cup's seals and holds."""

    tilts: np.ndarray
    fits: 'tuple[GraspFit, ...]'
    finger_depths: tuple[float, ...]
    free_axes: np.ndarray
    shapes: 'tuple[tuple[Shape, ...], ...]'
    usable: np.ndarray
    seals: 'tuple[Seal, ...]' = ()
    holds: 'tuple[Holding, ...]' = ()


class Kind:
    """What every kind shares: its keys' values checked against their limits, and its values
    by field."""

    KEYS: ClassVar[tuple[Key, ...]]
    kind: ClassVar[str]

    def check(self):
        """This gripper, each key within its limit (InvalidArgument naming gripper.<field>)."""
        for key in self.KEYS:
            key.limit.check(f'gripper.{key.field}', getattr(self, key.field))
        return self

    def file_values(self) -> dict[str, float]:
        """Every key in the experiment file's units, by its file key (6 decimals)."""
        return {k.file_key: round(getattr(self, k.field) / k.factor, 6) for k in self.KEYS}

    def values(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def with_values(self, **changed: float):
        return replace(self, **changed)
