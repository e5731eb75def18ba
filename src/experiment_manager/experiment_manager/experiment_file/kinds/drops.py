"""drop_test: single parts dropped onto a plate of the container's surface, the aspect each
comes to rest on counted against the user's own drops (analysis/drop_tests.py)."""

from typing import Any, ClassVar

from .. import experiment_keys
from ..drop_test import drop_test
from ..model import DROP_TEST, DropTestExperiment, Experiment
from .base import ExperimentKind


class DropTest(ExperimentKind):
    """One part per drop on its plate; no stage 4 (a single part has no neighbours)."""

    name: ClassVar[str] = DROP_TEST
    keys: ClassVar[type] = experiment_keys.DropTestKeys
    record: ClassVar[type] = DropTestExperiment
    checks_neighbours: ClassVar[bool] = False
    names_aspects: ClassVar[bool] = True

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        base = {k: out[k] for k in ('id', 'iterations')}
        return [self.record(**base, **drop_test(e, where, c.geometry, c.bin_wall))]
