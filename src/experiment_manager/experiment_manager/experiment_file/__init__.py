"""The experiment file: what a run uses of it, in SI units (`model`); the file as written, its
keys, types, ranges and defaults (`schema`, pydantic models of the `values` the cores'
rules check); reading and checking it with every error at once (`loading`; the part section,
its CAD file and grasps, in `part`), named by key path (`errors`); the experiment kinds, a
class per type in one registry (`kinds`); the iterations it asks for, each with its seed
(`plan`); and what a run ran with, every default applied (`resolved`). Pure: no rclpy, no
simulator.

The names users call are here: `load`, `parse`, `reduced`, `InvalidFile`, and the model's
types and constants.
"""

from .loading import InvalidFile, load, parse, reduced
from .model import (
    ADAPTIVE,
    BIN_EMPTYING,
    BIN_STATIC,
    BinEmptyingExperiment,
    BinStaticExperiment,
    Cell,
    DROP_TEST,
    DropTestExperiment,
    Experiment,
    ExperimentFile,
    FEEDER_EMPTYING,
    FeederEmptyingExperiment,
    FIXED,
    GRIPPER_SWEEP,
    GripperSweepExperiment,
    GripperVariant,
    MAX_ITERATIONS,
    MM,
    Ran,
    Requirements,
    Sampling,
    SEARCH_ORDERS,
    SENSITIVITY,
    SensitivityExperiment,
    TABLE_SWEEP,
    TableSweepExperiment,
    TYPES,
)

__all__ = [
    'ADAPTIVE', 'BIN_EMPTYING', 'BIN_STATIC', 'BinEmptyingExperiment', 'BinStaticExperiment',
    'Cell', 'DROP_TEST', 'DropTestExperiment', 'Experiment', 'ExperimentFile', 'FEEDER_EMPTYING',
    'FeederEmptyingExperiment', 'FIXED', 'GRIPPER_SWEEP', 'GripperSweepExperiment',
    'GripperVariant', 'InvalidFile', 'load', 'MAX_ITERATIONS', 'MM', 'parse', 'Ran', 'reduced',
    'Requirements', 'Sampling', 'SEARCH_ORDERS', 'SENSITIVITY', 'SensitivityExperiment',
    'TABLE_SWEEP', 'TableSweepExperiment', 'TYPES',
]
