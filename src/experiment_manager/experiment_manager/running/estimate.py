"""How long the rest of a run will take, from what its finished iterations cost.

Iterations of different experiments differ a hundredfold in cost (a 60-part sweep drop against
a feeder run of hundreds of vibrations), so the iterations left are weighed, not counted: an
iteration costs its cost units (its parts, times its grippers in a gripper_sweep) at the
seconds per unit that the finished iterations of its experiment took; before one of them has
finished, at its type's measured rate on this project's machine (PRIOR), scaled by how much
faster or slower the run's finished iterations went than their own types' PRIOR said (this
machine, this part); before any iteration has finished, at PRIOR itself. An iteration is not
split between workers: the time left is at least the dearest iteration left. Counting
iterations said 0:00:00 at 44 of 46 iterations, before two feeder runs that took 31 s; a
feeder run weighed at 200 sweep parts a part (a file whose feeder vibrated to its limit) said
0:06:19 at 18 s into PTH2's reduced run, which ended at 1:46.
"""

from collections.abc import Iterable

from ..experiment_file import (
    BIN_EMPTYING,
    BIN_STATIC,
    DROP_TEST,
    Experiment,
    FEEDER_EMPTYING,
    GRIPPER_SWEEP,
    TABLE_SWEEP,
)
from ..experiment_file.kinds import kind_of

# Seconds per cost unit of each type, measured: the reduced test case (pth0/1/2.yaml with one
# iteration each, 2 workers on the project's 2-core machine; docs/benchmarks.md),
# iterations.csv wall_time over parts: sweep 149 s over 15,150 parts, static bins
# 360 s over 11,760, emptying 42 s over 1,200, feeder runs 225 s over 1,200; gripper_sweep
# from the small test file's run (0.1 s over 28 parts x 8 grippers).
PRIOR = {TABLE_SWEEP: 0.0098, BIN_STATIC: 0.031, BIN_EMPTYING: 0.035, FEEDER_EMPTYING: 0.19,
         GRIPPER_SWEEP: 0.00045, DROP_TEST: 0.031}     # a drop as a part of a static bin's


def units(exp: Experiment, parts: float) -> float:
    """The cost units of one iteration of `exp` with `parts` parts: its parts, times its
    grippers x grasp sets for a gripper_sweep (each checks the scene once)."""
    return kind_of(exp).cost_units(exp, parts)


def mean_units(exp: Experiment) -> float:
    """The cost units of an average iteration of `exp` (a table_sweep's over its counts)."""
    return units(exp, kind_of(exp).parts(exp))


class Costs:
    """The wall times of finished iterations, by experiment, and the time left they imply."""

    def __init__(self) -> None:
        self._done: dict[str, tuple[Experiment, float, float]] = {}   # id -> (exp, s, units)

    def add(self, exp: Experiment, parts: float, seconds: float) -> None:
        """An iteration of `exp` with `parts` parts took `seconds` of wall time."""
        _, s, u = self._done.get(exp.id, (exp, 0.0, 0.0))
        self._done[exp.id] = (exp, s + seconds, u + units(exp, parts))

    def _rate(self, exp: Experiment) -> float:
        """Seconds per cost unit for `exp`: its own; else its type's PRIOR times the run's
        speed against PRIOR so far (1 before anything finished)."""
        if exp.id in self._done:
            _, s, u = self._done[exp.id]
            if u > 0:
                return s / u
        expected = sum(u * PRIOR[e.type] for e, _, u in self._done.values())
        taken = sum(s for _, s, _ in self._done.values())
        return PRIOR[exp.type] * (taken / expected if expected > 0 else 1.0)

    def left(self, iterations: Iterable[tuple[Experiment, int]], workers: int) -> float:
        """Seconds until `iterations` (experiment, iterations left) are done on `workers`
        workers: their cost spread over the workers, and at least the dearest one."""
        each = [(n, self._rate(exp) * mean_units(exp)) for exp, n in iterations if n]
        if not each:
            return 0.0
        spread = sum(n * cost for n, cost in each) / max(1, workers)
        return max(spread, max(cost for _, cost in each))
