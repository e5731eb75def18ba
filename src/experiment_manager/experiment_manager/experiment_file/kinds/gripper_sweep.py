"""gripper_sweep: every gripper and grasp set of a grid checked on the same scenes (all four
stages), for the smallest gripper that gives enough valid parts."""

from typing import Any, ClassVar

from pick_common.containers import check_fits

from .. import experiment_keys, grippers
from ..model import Experiment, GRIPPER_SWEEP, GripperSweepExperiment
from .base import ExperimentKind
from .context import bin_or_source


class GripperSweep(ExperimentKind):
    """One scene per iteration (a bin, or the tray), checked once per variant: its decision
    reads checks.csv, and its cost is its parts times its variants."""

    name: ClassVar[str] = GRIPPER_SWEEP
    keys: ClassVar[type] = experiment_keys.GripperSweepKeys
    record: ClassVar[type] = GripperSweepExperiment
    uses_checks: ClassVar[bool] = True
    own_grippers: ClassVar[bool] = True

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        scene = bin_or_source(e.bin, e.parts, where, c)
        if not scene:       # no bin: the parts lie on the tray, as in a table_sweep
            check_fits(f'{where}.parts (tray_mm)', e.parts, c.geometry.volume, c.tray)
        return [self.record(**out, **scene, min_valid=e.min_valid,
                                variants=grippers.variants(e, where, c.gripper, c.grasps))]

    def cost_units(self, exp: GripperSweepExperiment, parts: float) -> float:
        return parts * len(exp.variants)
