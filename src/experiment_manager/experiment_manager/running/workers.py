"""Workers shared by runs that go on at once: several experiment files (a board's parts) side by
side on one set of backends, so that a worker one run leaves idle (its last iteration running
on another worker, or an adaptive batch not yet looked at) runs another's iteration.

A run holds a worker for one iteration (or for its start) at a time. Of the runs with an
iteration ready for a free worker, the one begun first (the lowest rank: the manager's order of
its goals) takes it: a later run only fills what the earlier ones leave idle, and the earlier
ones are never queued behind it by more than the iteration it has in flight. Which worker runs
which iteration changes no result (each iteration runs on a fresh scene with its own seed, and
each run puts its rows in plan order).
"""

from collections.abc import Callable
import threading

from .backend import Backend

# Runs a manager runs at once. Each holds an executor thread of the manager for its whole run;
# the others answer the workers' calls (MultiThreadedExecutor(num_threads=4) in
# experiment_manager_node.main). Two keep every worker busy: the later fills what the earlier
# leaves idle.
RUNS_AT_ONCE = 2


class Workers:
    """The backends' holders and what each backend was last given, under one condition that
    every run sharing them waits on (scheduler.Runner).

    taken: called (under the condition) with a backend and the run that takes it, before the
    run starts or runs anything on it: the manager routes the worker's topics to that run's
    recording."""

    def __init__(self, taken: Callable[[Backend, object], None] | None = None) -> None:
        self.cond = threading.Condition()
        self._taken = taken or (lambda backend, run: None)
        self._holder: dict[Backend, object] = {}   # backend -> the run holding it
        self._given: dict[Backend, tuple] = {}     # backend -> what it was last given
        self._runs: list = []                      # the runs sharing them, by rank
        self._ranks: dict[object, int] = {}        # run -> its rank

    def join(self, run, rank: int | None = None) -> None:
        """`run` shares the workers from now on, after the runs of a lower rank (`rank`:
        after every run joined so far when None)."""
        with self.cond:
            if rank is None:
                rank = max(self._ranks.values(), default=0) + 1
            self._ranks[run] = rank
            self._runs.append(run)
            self._runs.sort(key=self._ranks.__getitem__)

    def leave(self, run) -> None:
        with self.cond:
            self._runs.remove(run)
            del self._ranks[run]
            self.cond.notify_all()

    def free(self, backend: Backend, run) -> bool:
        """Whether `run` may take `backend` now: nobody holds it, and no run that joined
        earlier has an iteration ready for it (under the condition)."""
        if backend in self._holder:
            return False
        for other in self._runs:
            if other is run:
                return True
            if other.wants(backend):
                return False
        return True

    def take(self, backend: Backend, run) -> None:
        """`run` holds `backend` (under the condition, after `free`)."""
        self._holder[backend] = run
        self._taken(backend, run)

    def put_back(self, backend: Backend) -> None:
        with self.cond:
            del self._holder[backend]
            self.cond.notify_all()

    def holder(self, backend: Backend):
        """The run holding `backend`, or None."""
        with self.cond:
            return self._holder.get(backend)

    def given(self, backend: Backend) -> tuple | None:
        """What `backend` was last given (Runner: the run, the scenario, the gripper and the
        station), None when nothing."""
        return self._given.get(backend)

    def give(self, backend: Backend, what: tuple) -> None:
        self._given[backend] = what
