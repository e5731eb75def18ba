"""The plan of a run: the iterations (units) of each experiment and their seeds.

Every iteration is a unit of work with its own seed, derived from the file's seed, the
experiment id and the iteration's key (`iteration_seed`), on a fresh scene of one instance: its
result depends on nothing else, so order, resumption and the worker that ran it do not matter.
"""

from dataclasses import dataclass, replace
import math
import zlib

from feeder_controller.policy import FeederConfig
import numpy as np
from pick_common.containers import ContainerSpec, PACKING_LIMIT
from pick_common.specs import MAX_PARTS_PER_INSTANCE, MAX_SEED

from .kinds import kind_of
from .model import Experiment, ExperimentFile


def iteration_seed(seed: int, experiment_id: str, key: tuple[int, ...]) -> int:
    """The seed of one iteration, from the file's seed, the experiment id and the iteration's
    key ((bin index, i) for bin_static, (n, i) for table_sweep, (i,) otherwise)."""
    words = [seed & 0xFFFFFFFF, seed >> 32, zlib.crc32(experiment_id.encode()), *key]
    state = np.random.SeedSequence(words).generate_state(1, np.uint64)[0]
    return int(state) & MAX_SEED


@dataclass(frozen=True)
class Unit:
    """One iteration: experiment, key (group, iteration), seed and what it runs on.
    group: the bin index for bin_static, n for table_sweep, 0 otherwise."""

    experiment: Experiment
    group: int
    iteration: int
    seed: int
    container: ContainerSpec
    parts: int
    feeder: FeederConfig | None = None

    @property
    def key(self) -> tuple[str, int, int]:
        """(experiment id, group, iteration): the key of its rows in the results files."""
        return self.experiment.id, self.group, self.iteration

    @property
    def label(self) -> str:
        """The iteration as a progress line says it (its kind's label)."""
        return kind_of(self.experiment).label(self.experiment, self.group, self.iteration)


EXTEND_STEPS = 3    # counts a table_sweep adds at a time while its fit still rises at its last


def held(file: ExperimentFile, exp: Experiment) -> int | None:
    """The most parts a feeder run holds among the feeder_emptying experiments that take
    their optimal range from `exp` (a table_sweep); None when none does.

    Such a feeder puts a shortfall on the table only while the table holds fewer than the
    range's min* (feeder_controller.policy): with min* at or above the parts it holds, it puts
    every part on the table (or doses them all, with max_feed) whatever the range is, so its
    runs are the same for any such range. A sweep whose optimum is known to give such a range
    needs no more drops, nor more counts, for them (sampling.range_unread)."""
    parts = [e.parts for e in file.experiments if getattr(e, 'range_from', '') == exp.id]
    return max(parts) if parts else None


def extended(file: ExperimentFile, exp: Experiment, summary) -> Experiment | None:
    """A table_sweep whose n* (`summary`, its metrics) sits at its last count, with up to
    EXTEND_STEPS more counts at its step, as many as fit the tray with the sweep's margin
    (containers' packing rule) and the per-instance limit; None when n* lies inside its counts,
    no part was valid, no more fit, the sweep says `extend: false`, or its range already
    starts at or above the parts of every feeder run that reads it (`held`: a higher n* would
    change none of their runs)."""
    if (not kind_of(exp).extends or not exp.extend or summary.no_valid
            or summary.n_star is None):
        return None
    last = exp.counts[-1]
    if summary.n_star < last:
        return None
    most_held = held(file, exp)
    if most_held is not None and summary.optimal_range[0] >= most_held:
        return None
    step = exp.counts[1] - exp.counts[0] if len(exp.counts) > 1 else 1
    most = MAX_PARTS_PER_INSTANCE
    if file.part_volume > 0:
        most = min(most, int(PACKING_LIMIT * math.prod(file.tray.inner_size) / file.part_volume))
    more = tuple(n for n in range(last + step, last + step * EXTEND_STEPS + 1, step)
                 if n + exp.margin <= most)
    return replace(exp, counts=exp.counts + more) if more else None


def groups(exp: Experiment) -> list[int]:
    """The groups of `exp`'s iterations (Unit.group), its kind's: its bins' indexes, its
    counts, or 0; none for a sensitivity experiment (its repeats are experiments of their
    own)."""
    return kind_of(exp).groups(exp)


def experiment_iterations(exp: Experiment) -> int:
    """The iterations of `exp`: its iterations per bin (bin_static) or per n (table_sweep)."""
    return len(groups(exp)) * exp.iterations


def count_iterations(file: ExperimentFile) -> int:
    return sum(experiment_iterations(e) for e in file.experiments)


def plan(file: ExperimentFile, exp: Experiment, summary: dict) -> list[Unit]:
    """The iterations of `exp`, given the summaries of the experiments before it (by id,
    analysis.summary's records: this room reads their fields, never imports them). A
    sensitivity scenario's repeat runs on the seeds of the experiment it repeats
    (scenarios.py)."""
    seeded_by = exp.seeded_by or exp.id.partition('@')[0]
    return [Unit(exp, group, i, iteration_seed(file.seed, seeded_by, (group, i)), container,
                 parts, feeder)
            for group, container, parts, feeder in kind_of(exp).scenes(file, exp, summary)
            for i in range(exp.iterations)]
