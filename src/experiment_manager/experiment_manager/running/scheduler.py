"""The scheduler of a run: spreads the iterations of a file's experiments over one or more
workers (backends), each iteration as soon as its experiment is ready, and hands every finished
iteration to the sink at once.

An experiment is ready when the experiments it takes its bin or range from have finished (their
metrics make its plan: plan.py), a sensitivity experiment when its repeats have (it runs
nothing of its own: its summary compares theirs); what one iteration does is procedures.py;
a scenario's repeat runs with the scenario's setup and moves (ExperimentFile.for_experiment),
given to a worker's backend when it changes. With adaptive
sampling an experiment's iterations are released a batch per group at a time, while its
decision is not settled (sampling.py). A worker that is lost gives its iteration back to the
queue and may come back (Backend.rejoin).
"""

import collections
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
import heapq
import threading
import time
from typing import Protocol

from ..analysis import metrics
from ..analysis.records import Sampling
from ..analysis.redecide import summarise
from ..analysis.rows import Record
from ..analysis.summary import Experiment as ExperimentSummary
from ..analysis.summary import Summary
from ..experiment_file import Experiment, ExperimentFile
from ..experiment_file.kinds import kind_of
from ..experiment_file.plan import count_iterations, experiment_iterations, extended, plan, Unit
from . import sampling
from .backend import Backend, WorkerLost
from .estimate import Costs
from .procedures import run_unit
from .workers import Workers


@dataclass(frozen=True)
class Progress:
    experiment_id: str
    experiment_type: str
    phase: str
    done: int
    total: int
    elapsed: float          # s
    eta: float              # s (estimate.py: the iterations left, weighed); 0 when none left


class Sink(Protocol):
    def is_done(self, experiment_id: str, group: int, iteration: int) -> bool: ...
    def write(self, record: Record) -> None: ...
    def iterations(self, experiment_id: str) -> list[dict]: ...
    def picks(self, experiment_id: str) -> list[dict]: ...
    def checks(self, experiment_id: str) -> list[dict]: ...
    def write_summary(self, summary: Summary) -> None: ...
    def reorder(self, rank: dict[tuple, tuple[int, int]]) -> None: ...


class Runner:
    """Runs the experiments of a file over one or more backends (workers), writing each
    iteration to the sink as it finishes.

    The iterations are spread over the workers, each taking the first ready one in plan order
    when it is free. An experiment is ready when the experiments it takes its bin or range from
    have finished (their metrics make its plan); the others run alongside, so a long iteration
    does not leave the other workers idle. When an experiment finishes, the sink puts the rows
    in plan order, so the results do not depend on how many workers ran them or which. `abort`
    is set when the run fails, so that the other workers' calls stop. Runs given the same
    `workers` (workers.py) go on side by side on the backends they share, the lowest `rank`
    (default: the first to run) first.
    """

    def __init__(self, file: ExperimentFile, backends: Sequence[Backend], sink: Sink,
                 progress: Callable[[Progress], None] | None = None,
                 abort: threading.Event | None = None, workers: Workers | None = None,
                 rank: int | None = None) -> None:
        if not backends:
            raise ValueError('a run needs at least one backend')
        self.file, self.backends, self.sink = file, list(backends), sink
        self._progress = progress or (lambda p: None)
        self._abort = abort or threading.Event()
        self._workers = workers or Workers()
        self._cond, self._joins_at = self._workers.cond, rank   # shared with the runs beside
        self._in_flight = 0
        self._rejoining = 0
        self._live = list(range(len(self.backends)))
        self._total = count_iterations(file)
        self._done = 0
        self._costs = Costs()
        self._start = time.monotonic()
        self._summary: dict[str, ExperimentSummary] = {}
        self._rank: dict[tuple, tuple[int, int]] = {}   # key -> (experiment, plan position)
        self._ready: list[tuple[tuple[int, int], Unit]] = []    # a heap by rank
        self._left: dict[str, int] = {}                # planned experiment -> units unwritten
        # adaptive sampling: experiment -> group -> its units not released yet, in order;
        # experiment -> the (group, iteration) of its units released; and -> batches released
        self._unreleased: dict[str, dict[int, list[Unit]]] = {}
        self._released: dict[str, set[tuple[int, int]]] = {}
        self._looks: dict[str, int] = {}
        self._waiting = list(file.experiments)         # not planned yet
        self._errors: list[BaseException] = []
        self.rejoined: list[int] = []     # indexes of the backends that came back, in order

    @property
    def lost_workers(self) -> list[int]:
        """Indexes of the backends whose worker was missing at the start or lost since."""
        return [k for k in range(len(self.backends)) if k not in self._live]

    def run(self) -> Summary:
        """Run every experiment; returns the summary (also written to the sink). A worker
        missing at the start is left out; the run fails when all are."""
        self._workers.join(self, self._joins_at)
        try:
            self._run()
        finally:
            self._workers.leave(self)
        if self._errors:
            raise self._errors[0]
        if self._waiting or any(self._left.values()):
            raise AssertionError('the run ended with iterations left undone')
        self._report(self.file.experiments[-1], 'done')
        return metrics.file_summary(self.file.ran, self._ordered_summary())

    def _run(self) -> None:
        # A backend another run holds is started when this run first takes it (_work).
        missing = []
        for k, backend in enumerate(self.backends):
            with self._cond:
                if not self._workers.free(backend, self):
                    continue
                self._workers.take(backend, self)
            try:
                backend.start(self.file)
                self._workers.give(backend, (self, None, '', False))
            except WorkerLost as exc:
                missing.append(exc)
                self._live.remove(k)
            finally:
                self._workers.put_back(backend)
        if not self._live:
            raise missing[0]
        with self._cond:
            self._guarded(self._release)
        workers = [threading.Thread(target=self._work, args=(k,), name=f'worker {k}')
                   for k in self._live]
        if len(workers) == 1:
            workers[0].run()
        else:
            for t in workers:
                t.start()
            for t in workers:
                t.join()

    def stop(self, exc: BaseException) -> None:
        """End the run with `exc` (canceled), even while it waits for a worker: run() raises
        it once the iterations in flight end."""
        with self._cond:
            self._errors.append(exc)
            self._abort.set()
            self._cond.notify_all()

    def wants(self, backend) -> bool:
        """Whether this run has an iteration ready for `backend` (under the condition)."""
        return (bool(self._ready) and not self._errors and not self._abort.is_set()
                and any(b is backend for k, b in enumerate(self.backends) if k in self._live))

    def _ordered_summary(self) -> dict:
        return {e.id: self._summary[e.id] for e in self.file.experiments
                if e.id in self._summary}

    def _guarded(self, step: Callable[..., None], *args) -> None:
        """Run a step under the lock; an error stops every worker and ends the run."""
        try:
            step(*args)
        except BaseException as exc:
            self._errors.append(exc)
            self._abort.set()

    def _release(self) -> None:
        """Plan the experiments whose sources have finished (under the lock)."""
        changed = True
        while changed:
            changed = False
            for exp in list(self._waiting):
                if exp not in self._waiting or not all(s in self._summary for s in exp.sources):
                    continue     # planned meanwhile (by the release a _finish made), or not yet
                self._waiting.remove(exp)
                index = self.file.experiments.index(exp)
                units = plan(self.file, exp, self._summary)
                for i, u in enumerate(units):
                    self._rank[u.key] = (index, i)
                self._left[exp.id] = 0
                if self.file.sampling.adaptive:
                    unreleased: dict[int, list[Unit]] = {}
                    for u in units:
                        unreleased.setdefault(u.group, []).append(u)
                    self._unreleased[exp.id] = unreleased
                    self._released[exp.id] = set()
                    self._looks[exp.id] = 0
                    self._next_batch(exp, list(unreleased))
                else:
                    self._queue(exp, units)
                    if not self._left[exp.id]:
                        self._finish(exp)
                changed = True

    def _queue(self, exp: Experiment, units: list[Unit]) -> None:
        """Queue the units not written yet (a resumed run wrote some) (under the lock)."""
        for u in units:
            if self.sink.is_done(*u.key):
                self._done += 1
            else:
                heapq.heappush(self._ready, (self._rank[u.key], u))
                self._left[exp.id] += 1

    def _next_batch(self, exp: Experiment, groups: list[int]) -> None:
        """Release the next batch of an adaptive experiment's `groups` (a group listed k times:
        k batches); while a batch was all written already (a resumed run), look at the rows
        again; finish the experiment when its decision is settled or its iterations are spent
        (under the lock)."""
        unreleased, batch = self._unreleased[exp.id], self.file.sampling.batch
        while True:
            wanted = collections.Counter(groups)
            units = [u for g, k in wanted.items() for u in unreleased[g][:k * batch]]
            for g, k in wanted.items():
                del unreleased[g][:k * batch]
            if not units:
                self._total -= sum(map(len, unreleased.values()))     # not needed
                unreleased.clear()
                self._finish(exp)
                return
            self._looks[exp.id] += 1
            self._released[exp.id].update((u.group, u.iteration) for u in units)
            self._queue(exp, units)
            if self._left[exp.id]:
                return
            groups = self._unsettled(exp)

    def _unsettled(self, exp: Experiment) -> list[int]:
        """The groups of an adaptive experiment that need more iterations and have some.
        It looks at the rows of the batches released so far only: a resumed run may have
        written rows of later ones (in flight when the run was cut), which the uncut run's look
        at this point had not seen."""
        released = self._released[exp.id]
        rows = [r for r in self.sink.iterations(exp.id)
                if (r['group'], r['iteration']) in released]
        checks = ([c for c in self.sink.checks(exp.id) if (c['group'], c['iteration']) in released]
                  if kind_of(exp).uses_checks else [])
        return [g for g in sampling.unsettled(self.file, exp, rows, checks)
                if self._unreleased[exp.id].get(g)]

    def _finish(self, exp: Experiment) -> None:
        """An experiment's last iteration is written: order the rows, summarise, release the
        experiments waiting for it (under the lock)."""
        self.sink.reorder(self._rank)
        rows, checks = self.sink.iterations(exp.id), self.sink.checks(exp.id)
        self._summary[exp.id] = summarise(self.file.ran, exp, rows, self.sink.picks(exp.id),
                                          checks, self._summary)
        wider = extended(self.file, exp, self._summary[exp.id])
        if wider is not None:       # a sweep still rising at its last count goes on
            del self._summary[exp.id]
            self._extend(exp, wider)
            return
        if self.file.sampling.adaptive and not kind_of(exp).repeats_others:
            self._summary[exp.id] = self._summary[exp.id].model_copy(
                update={'sampling': self._sampling(exp, rows, checks)})
        self.sink.write_summary(metrics.file_summary(self.file.ran, self._ordered_summary()))
        self._release()

    def _sampling(self, exp: Experiment, rows: list[dict], checks: list[dict]) -> Sampling:
        """How an adaptive experiment was sampled: its batches, iterations, whether its
        decision settled, and the bins left tied or known to tie (sampling.ended)."""
        left, tie = sampling.ended(self.file, exp, rows, checks)
        said = {}
        if left and kind_of(exp).groups_are_bins:       # the bins that could not be told apart
            said = {'tied_bins': left, 'race_confidence': sampling.RACE_CONFIDENCE}
        elif tie:                                       # bins known to tie within BIN_TIE
            said = {'tie': tie, 'tie_within': sampling.BIN_TIE,
                    'race_confidence': sampling.RACE_CONFIDENCE}
        if not left and kind_of(exp).extends:
            said = {'held': sampling.range_unread(self.file, exp, rows)}
        return Sampling(mode=self.file.sampling.mode, batch=self.file.sampling.batch,
                        batches=self._looks[exp.id], iterations_run=len(rows),
                        most=experiment_iterations(exp), settled=not left, **said)

    def _extend(self, exp: Experiment, wider: Experiment) -> None:
        """Run a table_sweep on at more counts (plan.extended): the file holds `wider` from
        now on, and its new counts' iterations are queued, or released as batches when
        adaptive; its experiments waiting on it wait on (under the lock)."""
        self.file = replace(self.file, experiments=tuple(
            wider if e.id == exp.id else e for e in self.file.experiments))
        index = self.file.experiments.index(wider)
        start = sum(1 for key in self._rank if key[0] == exp.id)
        units = [u for u in plan(self.file, wider, self._summary) if u.group not in exp.counts]
        for i, u in enumerate(units):
            self._rank[u.key] = (index, start + i)
        self._total += len(units)
        if self.file.sampling.adaptive:
            unreleased: dict[int, list[Unit]] = {}
            for u in units:
                unreleased.setdefault(u.group, []).append(u)
            self._unreleased[exp.id].update(unreleased)
            self._next_batch(wider, list(unreleased))
        else:
            self._queue(wider, units)
            if not self._left[exp.id]:
                self._finish(wider)

    def _work(self, k: int) -> None:
        """Worker k's loop: take the first ready iteration, run it, write it. While others are
        in flight it waits rather than leave: their end may release an experiment, and a lost
        worker's iteration comes back to the queue. It takes the worker for the iteration
        only (Workers): a run beside this one may run one of its own on it in between."""
        backend, workers = self.backends[k], self._workers
        while True:
            with self._cond:
                while not self._errors and not self._abort.is_set() and (
                        self._ready and not workers.free(backend, self)
                        or not self._ready and self._in_flight):
                    self._cond.wait()
                if self._errors or not self._ready or self._abort.is_set():
                    return
                _, u = heapq.heappop(self._ready)
                workers.take(backend, self)
                self._in_flight += 1
                self._report(u.experiment, f'{u.experiment.id}: {u.label}')
            try:
                file = self.file.for_experiment(u.experiment)
                # what `backend` was last given: the run, the scenario, the gripper and the
                # station (None, '', False: the file's)
                wanted = (self, u.experiment.scenario, u.experiment.gripper,
                          u.experiment.station)
                given = workers.given(backend)
                if (given is None or wanted[0] is not given[0] or wanted[1] is not given[1]
                        or wanted[2:] != given[2:]):
                    backend.start(file)
                    workers.give(backend, wanted)
                record = run_unit(file, u, backend)
            except WorkerLost as exc:
                with self._cond:
                    heapq.heappush(self._ready, (self._rank[u.key], u))
                    self._live.remove(k)
                    self._rejoining += 1
                    self._in_flight -= 1
                    self._cond.notify_all()
                back = backend.rejoin(self._over)
                with self._cond:
                    workers.put_back(backend)
                    self._rejoining -= 1
                    if back and not self._over():
                        self._live.append(k)
                        self.rejoined.append(k)
                        continue
                    if not self._live and not self._rejoining and not self._errors:
                        self._errors.append(exc)
                        self._abort.set()
                    self._cond.notify_all()
                return
            except BaseException as exc:
                with self._cond:
                    workers.put_back(backend)
                    self._errors.append(exc)
                    self._abort.set()
                    self._in_flight -= 1
                    self._cond.notify_all()
                return
            with self._cond:
                workers.put_back(backend)
                self._in_flight -= 1
                self._costs.add(u.experiment, u.parts, record.iteration['wall_time'])
                self._guarded(self._written, u, record)
                self._cond.notify_all()

    def _over(self) -> bool:
        """The run has failed, or has nothing left to run: a lost worker stops waiting."""
        return bool(self._errors) or self._abort.is_set() or not (
            self._ready or self._in_flight or self._waiting)

    def _written(self, u: Unit, record: Record) -> None:
        self.sink.write(record)
        self._done += 1
        exp = u.experiment
        self._left[exp.id] -= 1
        if self._left[exp.id]:
            return
        if self.file.sampling.adaptive:
            self._next_batch(exp, self._unsettled(exp))
        else:
            self._finish(exp)

    def _report(self, exp: Experiment, phase: str) -> None:
        # an adaptive experiment's iterations not released yet count: the ETA is of the most
        # it may take, as the total is
        left = [(e, self._left[e.id] + sum(map(len, self._unreleased.get(e.id, {}).values())))
                for e in self.file.experiments if e.id in self._left]
        left += [(e, experiment_iterations(e)) for e in self._waiting]
        eta = self._costs.left(left, len(self._live))
        self._progress(Progress(exp.id, exp.type, phase, self._done, self._total,
                                time.monotonic() - self._start, eta))
