"""The experiment kinds, one class each, found by the file's `type` in `KINDS`: the paper's
four (section 4.3: bins.BinStatic, bins.BinEmptying, table.TableSweep, table.FeederEmptying)
and ours (gripper_sweep.GripperSweep, drops.DropTest, sensitivity.Sensitivity). A kind owns,
in this room: its keys (a model of experiment_keys), how its entry is read and checked
(`read`), its groups and scenes (`groups`, `scenes`; plan.py makes the iterations, each with
its seed), how a progress line names an iteration (`label`), its cost per iteration, and the
traits the later rooms read of it (base.ExperimentKind). What the later rooms do per kind,
which this room may not import (the package docstring's order), is one table each keyed by
the kind's name: metrics.SUMMARIES, sampling.DECISIONS, procedures.PROCEDURES and the report's
sections; a test holds every table to KINDS, and docs/extending.md lists them.
"""

from collections.abc import Mapping
from typing import Any

from ..experiment_keys import ExperimentKeys
from ..schema import Section
from .base import ExperimentKind, kind_of, KINDS, Scene
from .bins import BinEmptying, BinStatic
from .context import Context
from .drops import DropTest
from .gripper_sweep import GripperSweep
from .sensitivity import Sensitivity
from .table import FeederEmptying, TableSweep

__all__ = ['Context', 'ExperimentKind', 'keys_model', 'KINDS', 'kind_of', 'Scene']

KINDS.update({k.name: k() for k in (BinStatic, BinEmptying, TableSweep, FeederEmptying,
                                     GripperSweep, DropTest, Sensitivity)})


class _AnyExperiment(ExperimentKeys):
    """An entry of an unknown or missing type: its type's error and its id's and
    iterations', but no key named unknown."""

    model_config = {**ExperimentKeys.model_config, 'extra': 'ignore'}


def keys_model(item: Any) -> type[Section]:
    """The model an experiment is read with: its kind's keys, or (for an unknown or missing
    type) one that names the type's error and its id's and iterations' but no key as
    unknown."""
    kind = item.get('type') if isinstance(item, Mapping) else None
    if isinstance(kind, str) and kind in KINDS:
        return KINDS[kind].keys
    return _AnyExperiment
