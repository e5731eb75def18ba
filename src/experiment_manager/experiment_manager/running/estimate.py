"""How long the rest of a run will take, from what its finished iterations cost.

Iterations of different experiments differ a hundredfold in cost (a 60-part sweep drop against
a feeder run of hundreds of vibrations), so the iterations left are weighed, not counted: an
iteration costs its cost units (its parts, times its grippers in a gripper_sweep, times its
type's weight) at the seconds per unit that the finished iterations of its experiment took;
before one of them has finished, at the rate of its type's finished iterations, and before any
of its type, at the rate of all. Counting iterations instead said 0:00:00 at 44 of 46
iterations, before two feeder runs that took 31 s (issue 23).
"""

from collections.abc import Iterable

import numpy as np

from ..experiment_file import Experiment, FEEDER_EMPTYING, GRIPPER_SWEEP, TABLE_SWEEP

# A type's cost per part against the others', for an experiment whose type has no finished
# iteration yet. The built-in file's run (2026-11-25, 2 workers, iterations.csv wall_time /
# parts): feeder runs 1.53 s per part (they vibrate to their limit), every other type 0.007 to
# 0.012 s. Without it, at 44 of 51 iterations the estimate said 7 s before two feeder runs of
# 92 s each.
TYPE_WEIGHT = {FEEDER_EMPTYING: 200.0}


def units(exp: Experiment, parts: float) -> float:
    """The cost units of one iteration of `exp` with `parts` parts: its parts, times its
    grippers x grasp sets for a gripper_sweep (each checks the scene once), times its type's
    weight."""
    return (parts * (len(exp.variants) if exp.type == GRIPPER_SWEEP else 1)
            * TYPE_WEIGHT.get(exp.type, 1.0))


def mean_units(exp: Experiment) -> float:
    """The cost units of an average iteration of `exp` (a table_sweep's over its counts)."""
    return units(exp, float(np.mean(exp.counts)) if exp.type == TABLE_SWEEP else exp.parts)


class Costs:
    """The wall times of finished iterations, by experiment, and the time left they imply."""

    def __init__(self) -> None:
        self._done: dict[str, tuple[Experiment, float, float]] = {}   # id -> (exp, s, units)

    def add(self, exp: Experiment, parts: float, seconds: float) -> None:
        """An iteration of `exp` with `parts` parts took `seconds` of wall time."""
        _, s, u = self._done.get(exp.id, (exp, 0.0, 0.0))
        self._done[exp.id] = (exp, s + seconds, u + units(exp, parts))

    def _rate(self, exp: Experiment) -> float | None:
        """Seconds per cost unit for `exp`: its own, its type's, everyone's; None if none ran."""
        for chosen in ([v for k, v in self._done.items() if k == exp.id],
                       [v for v in self._done.values() if v[0].type == exp.type],
                       list(self._done.values())):
            u = sum(v[2] for v in chosen)
            if u > 0:
                return sum(v[1] for v in chosen) / u
        return None

    def left(self, iterations: Iterable[tuple[Experiment, int]], workers: int) -> float:
        """Seconds until `iterations` (experiment, iterations left) are done on `workers`
        workers; 0 when nothing has finished yet (unknown)."""
        total = 0.0
        for exp, n in iterations:
            rate = self._rate(exp) if n else 0.0
            if rate is None:
                return 0.0
            total += n * rate * mean_units(exp)
        return total / max(1, workers)
