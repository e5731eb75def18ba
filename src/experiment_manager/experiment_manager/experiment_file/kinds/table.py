"""The paper's two table experiments (section 4.3.2): table_sweep, n parts on the tray for
each n, checked (all four stages), whose fit gives the optimal range; and feeder_emptying,
the feeder and the vibrating table run by the optimal-range policy until they are empty."""

from typing import Any, ClassVar

from feeder_controller.policy import check_feeder, FeederConfig
import numpy as np
from pick_common.containers import check_fits

from .. import experiment_keys
from ..errors import checked as checked_as
from ..model import (
    Experiment,
    ExperimentFile,
    FEEDER_EMPTYING,
    FeederEmptyingExperiment,
    TABLE_SWEEP,
    TableSweepExperiment,
)
from .base import ExperimentKind, Scene, scene_container
from .context import earlier


class TableSweep(ExperimentKind):
    """Its groups are its counts, each on the tray; it may go on at more counts while its fit
    still rises at its last (plan.extended)."""

    name: ClassVar[str] = TABLE_SWEEP
    keys: ClassVar[type] = experiment_keys.TableSweepKeys
    record: ClassVar[type] = TableSweepExperiment
    extends: ClassVar[bool] = True

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        out = {k: v for k, v in out.items() if k != 'parts'}     # its parts are its counts
        out['counts'] = tuple(range(e.counts.first, e.counts.last + 1, e.counts.step))
        check_fits(f'{where}.counts.last', out['counts'][-1], c.geometry.volume, c.tray)
        return [self.record(**out, margin=e.margin, extend=e.extend)]

    def groups(self, exp: TableSweepExperiment) -> list[int]:
        return list(exp.counts)

    def scenes(self, file: ExperimentFile, exp: TableSweepExperiment, summary: dict
               ) -> list[Scene]:
        return [(n, scene_container(file, exp, summary), n, None) for n in exp.counts]

    def label(self, exp: TableSweepExperiment, group: int, iteration: int) -> str:
        return f'{group} parts, iteration {iteration + 1}'

    def parts(self, exp: TableSweepExperiment) -> float:
        return float(np.mean(exp.counts))


class FeederEmptying(ExperimentKind):
    """The feeder's run on the tray, its range its own or a table_sweep's optimal range; a
    run cut short decides it."""

    name: ClassVar[str] = FEEDER_EMPTYING
    keys: ClassVar[type] = experiment_keys.FeederEmptyingKeys
    record: ClassVar[type] = FeederEmptyingExperiment
    left_out_settles: ClassVar[bool] = True
    feeds: ClassVar[bool] = True

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        if isinstance(e.optimal_range, str):
            source = earlier(f'{where}.optimal_range', e.optimal_range, c, TABLE_SWEEP,
                             '[min, max]')
            out['range_from'] = e.optimal_range
            high = source.counts[-1] + source.margin
        else:
            out['optimal_range'] = e.optimal_range
            high = e.optimal_range[1]
            checked_as(check_feeder, FeederConfig(e.parts, *e.optimal_range, e.max_vibrations,
                                                  e.max_feed or 0), where)
        check_fits(f'{where}.optimal_range (max)', high, c.geometry.volume, c.tray)
        return [self.record(**out, max_vibrations=e.max_vibrations,
                                max_feed=e.max_feed or 0)]

    def scenes(self, file: ExperimentFile, exp: FeederEmptyingExperiment, summary: dict
               ) -> list[Scene]:
        low, high = exp.optimal_range or summary[exp.range_from].optimal_range
        feeder = FeederConfig(exp.parts, low, high, exp.max_vibrations, exp.max_feed)
        return [(0, scene_container(file, exp, summary), exp.parts, feeder)]
