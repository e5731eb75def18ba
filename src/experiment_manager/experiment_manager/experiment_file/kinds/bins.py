"""The paper's two bin experiments (section 4.3.1): bin_static, every candidate bin filled
and checked (stages 1-3), and bin_emptying, one bin picked until no part is valid."""

from typing import Any, ClassVar

from pick_common.containers import check_fits

from .. import experiment_keys
from ..model import (
    BIN_EMPTYING,
    BIN_STATIC,
    BinEmptyingExperiment,
    BinStaticExperiment,
    Experiment,
    ExperimentFile,
)
from .base import ExperimentKind, Scene
from .context import bin_or_source, bin_spec


class BinStatic(ExperimentKind):
    """Its groups are its bins; a scene is checked without the neighbours' stage."""

    name: ClassVar[str] = BIN_STATIC
    keys: ClassVar[type] = experiment_keys.BinStaticKeys
    record: ClassVar[type] = BinStaticExperiment
    checks_neighbours: ClassVar[bool] = False
    groups_are_bins: ClassVar[bool] = True

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        out['bins'] = tuple(bin_spec(v, f'{where}.bins_mm[{i}]', c)
                            for i, v in enumerate(e.bins_mm))
        for i, b in enumerate(out['bins']):
            check_fits(f'{where}.parts (bins_mm[{i}])', e.parts, c.geometry.volume, b)
        return [self.record(**out)]

    def groups(self, exp: BinStaticExperiment) -> list[int]:
        return list(range(len(exp.bins)))

    def scenes(self, file: ExperimentFile, exp: BinStaticExperiment, summary: dict) -> list[Scene]:
        return [(b, container, exp.parts, None) for b, container in enumerate(exp.bins)]

    def label(self, exp: BinStaticExperiment, group: int, iteration: int) -> str:
        return f'bin {group + 1}/{len(exp.bins)}, iteration {iteration + 1}'


class BinEmptying(ExperimentKind):
    """One bin (its own, or the best of a bin_static); a run cut short decides it."""

    name: ClassVar[str] = BIN_EMPTYING
    keys: ClassVar[type] = experiment_keys.BinEmptyingKeys
    record: ClassVar[type] = BinEmptyingExperiment
    left_out_settles: ClassVar[bool] = True

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        return [self.record(**out, **bin_or_source(e.bin, e.parts, where, c))]
