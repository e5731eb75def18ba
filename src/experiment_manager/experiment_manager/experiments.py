"""The four experiment types (paper section 4.3), as plain Python over a `Backend`.

A backend does the physics and the checks: `LocalBackend` (local_backend.py) runs the cores in
this process; the node's `GraphBackend` calls the `world`, `validity` and `feeder_controller`
nodes. The experiment logic is the same for both, so it is tested here without a graph.

Every iteration is a unit of work with its own seed, derived from the file's seed, the
experiment id and the iteration's key (`iteration_seed`), on a fresh scene of one instance: its
result depends on nothing else, so order, resumption and the worker that ran it do not matter.
Each finished iteration is handed to the sink at once, as rows (see results.py for the columns).
"""

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
import heapq
import threading
import time
from typing import Protocol
import zlib

from feeder_controller.policy import (
    FeederConfig,
    PICK,
    STOP_EMPTY,
    STOP_VIBRATION_LIMIT,
)
from feeder_controller.policy import (
    NAMES as DECISION_NAMES,
)
import numpy as np
from pick_sim_world.config import MAX_SEED
from pick_sim_world.containers import ContainerSpec
from pick_sim_world.errors import PhysicsFault
from pick_sim_world.world import PartStates, SettleReport
from pick_validity.validity import Report, STAGE_NONE

from . import metrics
from .config import (
    BIN_EMPTYING,
    BIN_STATIC,
    Experiment,
    ExperimentFile,
    FEEDER_EMPTYING,
    TABLE_SWEEP,
)

MAX_FEED_CYCLES = 1_000_000     # a guard: the vibration limit ends a run long before
NEIGHBOUR_MARGIN = 1.0          # m beyond the container: farther parts are not checked


def iteration_seed(seed: int, experiment_id: str, key: tuple[int, ...]) -> int:
    """The seed of one iteration, from the file's seed, the experiment id and the iteration's
    key ((bin index, i) for bin_static, (n, i) for table_sweep, (i,) otherwise)."""
    words = [seed & 0xFFFFFFFF, seed >> 32, zlib.crc32(experiment_id.encode()), *key]
    state = np.random.SeedSequence(words).generate_state(1, np.uint64)[0]
    return int(state) & MAX_SEED


@dataclass(frozen=True)
class FeedStep:
    """What one feed_cycle did: the decision (feeder_controller.policy constants), parts fed,
    and the feeder's counts afterwards."""

    decision: int
    fed: int
    vibrations: int
    feeds: int
    in_feeder: int


class Backend(Protocol):
    """What an experiment needs done. Raises pick_sim_world.errors.WorldError subclasses for
    bad input and physics faults; a graph backend raises its own errors for lost nodes."""

    def start(self, file: ExperimentFile) -> None:
        """Take the part, the gripper and the check settings of the run."""

    def reset(self, container: ContainerSpec, seed: int) -> None:
        """A fresh scene of one instance with this container, seeded."""

    def drop(self, count: int, zone: str) -> tuple[PartStates, SettleReport]:
        """Drop parts ('container' or the tray's 'feeder' zone) and settle."""

    def remove(self, ids: list[int], settle: bool = True) -> tuple[PartStates, SettleReport]:
        """Remove parts (picked, or lost over the edge) and settle the rest."""

    def parts(self) -> PartStates:
        """The parts now."""

    def check(self, container: ContainerSpec, states: PartStates, targets: list[int],
              neighbours: bool) -> Report:
        """The staged checks of `targets` among every part of `states`."""

    def feed(self, valid: int, on_table: int, restart: FeederConfig | None) -> FeedStep:
        """One feeder policy step (restart: load the feeder first)."""

    def rejoin(self, stop: Callable[[], bool]) -> bool:
        """After WorkerLost: wait for the worker to come back; False if it does not (in the
        backend's own time) or once stop() holds."""


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


@dataclass
class Record:
    """The rows of one finished iteration."""

    iteration: dict
    checks: list[dict] = field(default_factory=list)
    parts: list[dict] = field(default_factory=list)
    picks: list[dict] = field(default_factory=list)


@dataclass(frozen=True)
class Progress:
    experiment_id: str
    experiment_type: str
    phase: str
    done: int
    total: int
    elapsed: float          # s
    eta: float              # s, 0 when unknown


class Sink(Protocol):
    def is_done(self, experiment_id: str, group: int, iteration: int) -> bool: ...
    def write(self, record: Record) -> None: ...
    def iterations(self, experiment_id: str) -> list[dict]: ...
    def picks(self, experiment_id: str) -> list[dict]: ...
    def write_summary(self, summary: dict) -> None: ...
    def reorder(self, rank: dict[tuple, tuple[int, int]]) -> None: ...


def count_iterations(file: ExperimentFile) -> int:
    total = 0
    for e in file.experiments:
        groups = len(e.bins) if e.type == BIN_STATIC else len(e.counts) or 1
        total += groups * e.iterations
    return total


def plan(file: ExperimentFile, exp: Experiment, summary: dict) -> list[Unit]:
    """The iterations of `exp`, given the metrics of the experiments before it."""
    units = []

    def unit(group: int, i: int, container: ContainerSpec, parts: int, **kw) -> Unit:
        return Unit(exp, group, i, iteration_seed(file.seed, exp.id, (group, i)), container,
                    parts, **kw)

    if exp.type == BIN_STATIC:
        for b, container in enumerate(exp.bins):
            units += [unit(b, i, container, exp.parts) for i in range(exp.iterations)]
    elif exp.type == BIN_EMPTYING:
        container = exp.bin
        if container is None:
            best = summary[exp.bin_from]['best_bin']
            container = file.experiment(exp.bin_from).bins[best]
        units = [unit(0, i, container, exp.parts) for i in range(exp.iterations)]
    elif exp.type == TABLE_SWEEP:
        for n in exp.counts:
            units += [unit(n, i, file.tray, n) for i in range(exp.iterations)]
    else:
        low, high = exp.optimal_range or summary[exp.range_from]['optimal_range']
        feeder = FeederConfig(exp.parts, low, high, exp.max_vibrations)
        units = [unit(0, i, file.tray, exp.parts, feeder=feeder)
                 for i in range(exp.iterations)]
    return units


def search_order(order: str, states: PartStates, targets: np.ndarray, seed: int) -> np.ndarray:
    """The order in which a picking cell would look at the target parts (ids).
    top_first: highest part origin first; id: by id; random: seeded shuffle."""
    if order == 'id':
        return np.sort(targets)
    if order == 'random':
        return np.random.default_rng(seed).permutation(np.sort(targets))
    z = dict(zip(states.ids.tolist(), states.poses[:, 2].tolist(), strict=True))
    return np.array(sorted(targets.tolist(), key=lambda i: (-z[i], i)), dtype=np.int64)


class WorkerLost(Exception):
    """A backend's worker died or stopped answering: its iteration in flight is run again on
    another worker, and this worker gets more only if it comes back (Backend.rejoin)."""


class Runner:
    """Runs the experiments of a file over one or more backends (workers), writing each
    iteration to the sink as it finishes.

    The iterations are spread over the workers, each taking the first ready one in plan order
    when it is free. An experiment is ready when the experiments it takes its bin or range from
    have finished (their metrics make its plan); the others run alongside, so a long iteration
    does not leave the other workers idle. When an experiment finishes, the sink puts the rows
    in plan order, so the results do not depend on how many workers ran them or which. `abort`
    is set when the run fails, so that the other workers' calls stop.
    """

    def __init__(self, file: ExperimentFile, backends: Sequence[Backend], sink: Sink,
                 progress: Callable[[Progress], None] | None = None,
                 abort: threading.Event | None = None) -> None:
        if not backends:
            raise ValueError('a run needs at least one backend')
        self.file, self.backends, self.sink = file, list(backends), sink
        self._progress = progress or (lambda p: None)
        self._abort = abort or threading.Event()
        self._cond = threading.Condition()
        self._in_flight = 0
        self._rejoining = 0
        self._live = list(range(len(self.backends)))
        self._total = count_iterations(file)
        self._done = 0
        self._ran = 0
        self._start = time.monotonic()
        self._summary: dict[str, dict] = {}
        self._rank: dict[tuple, tuple[int, int]] = {}   # key -> (experiment, plan position)
        self._ready: list[tuple[tuple[int, int], Unit]] = []    # a heap by rank
        self._left: dict[str, int] = {}                # planned experiment -> units unwritten
        self._waiting = list(file.experiments)         # not planned yet
        self._errors: list[BaseException] = []
        self.rejoined: list[int] = []     # indexes of the backends that came back, in order

    @property
    def lost_workers(self) -> list[int]:
        """Indexes of the backends whose worker was missing at the start or lost since."""
        return [k for k in range(len(self.backends)) if k not in self._live]

    def run(self) -> dict:
        """Run every experiment; returns the summary (also written to the sink). A worker
        missing at the start is left out; the run fails when all are."""
        missing = []
        for k, backend in enumerate(self.backends):
            try:
                backend.start(self.file)
            except WorkerLost as exc:
                missing.append(exc)
                self._live.remove(k)
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
        if self._errors:
            raise self._errors[0]
        if self._waiting or any(self._left.values()):
            raise AssertionError('the run ended with iterations left undone')
        self._report(self.file.experiments[-1], 'done')
        return metrics.file_summary(self.file, self._ordered_summary())

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
                sources = [s for s in (exp.bin_from, exp.range_from) if s]
                if exp not in self._waiting or not all(s in self._summary for s in sources):
                    continue     # planned meanwhile (by the release a _finish made), or not yet
                self._waiting.remove(exp)
                index = self.file.experiments.index(exp)
                units = plan(self.file, exp, self._summary)
                left = 0
                for i, u in enumerate(units):
                    key = (exp.id, u.group, u.iteration)
                    self._rank[key] = (index, i)
                    if self.sink.is_done(*key):
                        self._done += 1
                    else:
                        heapq.heappush(self._ready, ((index, i), u))
                        left += 1
                self._left[exp.id] = left
                if not left:
                    self._finish(exp)
                changed = True

    def _finish(self, exp: Experiment) -> None:
        """An experiment's last iteration is written: order the rows, summarise, release the
        experiments waiting for it (under the lock)."""
        self.sink.reorder(self._rank)
        self._summary[exp.id] = metrics.summarise(
            self.file, exp, self.sink.iterations(exp.id), self.sink.picks(exp.id),
            self._summary)
        self.sink.write_summary(metrics.file_summary(self.file, self._ordered_summary()))
        self._release()

    def _work(self, k: int) -> None:
        """Worker k's loop: take the first ready iteration, run it, write it. While others are
        in flight it waits rather than leave: their end may release an experiment, and a lost
        worker's iteration comes back to the queue."""
        backend = self.backends[k]
        while True:
            with self._cond:
                while not self._ready and self._in_flight and not self._errors:
                    self._cond.wait()
                if self._errors or not self._ready or self._abort.is_set():
                    return
                _, u = heapq.heappop(self._ready)
                self._in_flight += 1
                self._report(u.experiment, f'{u.experiment.id}: {_label(u)}')
            try:
                record = self.run_unit(u, backend)
            except WorkerLost as exc:
                with self._cond:
                    heapq.heappush(self._ready, (self._rank[_key_of(u)], u))
                    self._live.remove(k)
                    self._rejoining += 1
                    self._in_flight -= 1
                    self._cond.notify_all()
                back = backend.rejoin(self._over)
                with self._cond:
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
                    self._errors.append(exc)
                    self._abort.set()
                    self._in_flight -= 1
                    self._cond.notify_all()
                return
            with self._cond:
                self._in_flight -= 1
                self._guarded(self._written, u, record)
                self._cond.notify_all()

    def _over(self) -> bool:
        """The run has failed, or has nothing left to run: a lost worker stops waiting."""
        return bool(self._errors) or self._abort.is_set() or not (
            self._ready or self._in_flight or self._waiting)

    def _written(self, u: Unit, record: Record) -> None:
        self.sink.write(record)
        self._done += 1
        self._ran += 1
        self._left[u.experiment.id] -= 1
        if not self._left[u.experiment.id]:
            self._finish(u.experiment)

    def _report(self, exp: Experiment, phase: str) -> None:
        elapsed = time.monotonic() - self._start
        eta = elapsed / self._ran * (self._total - self._done) if self._ran else 0.0
        self._progress(Progress(exp.id, exp.type, phase, self._done, self._total, elapsed, eta))

    # ------------------------------------------------------------------------- one iteration
    def run_unit(self, u: Unit, backend: Backend) -> Record:
        """Run one iteration on `backend`; returns its rows."""
        start = time.monotonic()
        backend.reset(u.container, u.seed)
        run = {BIN_STATIC: self._static, TABLE_SWEEP: self._static,
               BIN_EMPTYING: self._emptying, FEEDER_EMPTYING: self._feeder}[u.experiment.type]
        record = Record(iteration={})
        try:
            row = run(u, record, backend)
        except PhysicsFault as exc:    # its seed would fault again: marked, not run again
            row = {'settled': False, 'escaped': 0, 'emptied': False, 'vibrations': 0,
                   'feeds': 0, 'lost': 0, 'stop': f'{metrics.PHYSICS_FAULT}: {exc}'}
        first = record.checks[0] if record.checks else {}
        x, y, z = u.container.inner_size
        record.iteration = {
            'experiment': u.experiment.id, 'type': u.experiment.type, 'group': u.group,
            'iteration': u.iteration, 'seed': u.seed, 'container_x': x, 'container_y': y,
            'container_z': z, 'parts': u.parts,
            **{k: first.get(k, 0) for k in ('checked', 'candidates', 'placeable',
                                             'container_free', 'valid')},
            'checks': len(record.checks), 'picks': len(record.picks),
            **row, 'fault': faults(row), 'wall_time': time.monotonic() - start}
        return record

    def _key(self, u: Unit) -> dict:
        return {'experiment': u.experiment.id, 'group': u.group, 'iteration': u.iteration}

    def _check(self, u: Unit, record: Record, backend: Backend, states: PartStates,
               neighbours: bool, vibrations: int = 0) -> tuple[Report | None, np.ndarray]:
        """Check the parts inside the container; record the check and every part's row.
        Returns the report (None when no part is inside) and the targets in search order."""
        targets = states.ids[states.inside]
        index = len(record.checks)
        row = {**self._key(u), 'check': index, 'parts_on_table': int(len(targets)),
               'checked': 0, 'candidates': 0, 'placeable': 0, 'container_free': 0, 'valid': 0,
               'picked_id': -1, 'searches': 0, 'vibrations': vibrations, 'wall_time': 0.0}
        report = None
        stages: dict[int, tuple[int, int, int]] = {}
        if len(targets):
            # Parts that left the container fall for ever (the world has no ground): those
            # NEIGHBOUR_MARGIN beyond it cannot touch a gripper at a part inside; not sent.
            reach = max(u.container.inner_size) + NEIGHBOUR_MARGIN
            near = np.abs(states.poses[:, :3]).max(axis=1) <= reach
            report = backend.check(u.container, states.masked(near), targets.tolist(),
                                   neighbours)
            row.update(report.counts)
            row['wall_time'] = report.wall_time
            stages = {r.part_id: (r.stage, r.grasp_index, len(r.valid_tilts))
                      for r in report.results}
        record.checks.append(row)
        for pid, pose, inside in zip(states.ids.tolist(), states.poses.tolist(),
                                     states.inside.tolist(), strict=True):
            stage, grasp, tilts = stages.get(pid, (STAGE_NONE, -1, 0))
            record.parts.append({**self._key(u), 'check': index, 'part_id': pid,
                                 **dict(zip(POSE, pose, strict=True)), 'inside': inside,
                                 'stage': stage, 'grasp': grasp, 'tilts': tilts})
        order = search_order(self.file.search_order, states, targets, u.seed + index)
        return report, order

    def _pick(self, u: Unit, record: Record, report: Report, order: np.ndarray,
              vibrations: int = 0) -> int:
        """Choose the first valid part in search order; record the pick. Returns its id."""
        by_id = {r.part_id: r for r in report.results}
        for searches, pid in enumerate(order.tolist(), start=1):
            result = by_id[pid]
            if result.valid:
                check = record.checks[-1]
                check['picked_id'], check['searches'] = pid, searches
                record.picks.append({
                    **self._key(u), 'pick': len(record.picks), 'check': check['check'],
                    'part_id': pid, 'searches': searches, 'vibrations': vibrations,
                    'grasp': result.grasp_index,
                    **dict(zip(GRIPPER_POSE, np.asarray(result.gripper_pose).tolist(),
                               strict=True))})
                return pid
        raise AssertionError('a report with valid parts has none in the search order')

    @staticmethod
    def _physics(reports: list[SettleReport]) -> dict:
        return {'settled': all(r.settled for r in reports),
                'escaped': len({i for r in reports for i in r.escaped_ids})}

    def _static(self, u: Unit, record: Record, backend: Backend) -> dict:
        """bin_static (stages 1-3) and table_sweep (all four stages): drop, settle, check."""
        states, settle = backend.drop(u.parts, 'container')
        self._check(u, record, backend, states, neighbours=u.experiment.type == TABLE_SWEEP)
        return {**self._physics([settle]), 'emptied': False, 'vibrations': 0, 'feeds': 0,
                'lost': 0, 'stop': ''}

    def _emptying(self, u: Unit, record: Record, backend: Backend) -> dict:
        """bin_emptying: check in search order, remove the first valid part, settle, repeat
        until none is valid or the bin is empty."""
        states, settle = backend.drop(u.parts, 'container')
        settles = [settle]
        stop = 'empty'
        while states.inside.any():
            report, order = self._check(u, record, backend, states, neighbours=True)
            if report.counts['valid'] == 0:
                stop = 'no valid part'
                break
            pid = self._pick(u, record, report, order)
            states, settle = backend.remove([pid])
            settles.append(settle)
        return {**self._physics(settles), 'emptied': not states.inside.any(), 'vibrations': 0,
                'feeds': 0, 'lost': int((~states.inside).sum()), 'stop': stop}

    def _feeder(self, u: Unit, record: Record, backend: Backend) -> dict:
        """feeder_emptying: the feeder loads the table up to max* and vibrates; then after each
        check the policy picks, vibrates, or feeds and vibrates, until it stops."""
        step = backend.feed(0, 0, u.feeder)
        states = backend.parts()
        settles: list[SettleReport] = []
        lost = 0
        for _ in range(MAX_FEED_CYCLES):
            outside = states.ids[~states.inside].tolist()
            if outside:     # over the edge: gone from the table, counted as lost
                lost += len(outside)
                states, settle = backend.remove(outside, settle=False)
            report, order = self._check(u, record, backend, states, neighbours=True,
                                        vibrations=step.vibrations)
            valid = report.counts['valid'] if report else 0
            step = backend.feed(valid, int(states.inside.sum()), None)
            if step.decision == PICK:
                pid = self._pick(u, record, report, order, step.vibrations)
                states, settle = backend.remove([pid])
                settles.append(settle)
            elif step.decision in (STOP_EMPTY, STOP_VIBRATION_LIMIT):
                break
            else:
                states = backend.parts()
        return {**self._physics(settles), 'emptied': step.decision == STOP_EMPTY and lost == 0,
                'vibrations': step.vibrations, 'feeds': step.feeds, 'lost': lost,
                'stop': DECISION_NAMES[step.decision]}


def faults(row: dict) -> str:
    """The physics faults of an iteration, '+'-joined ('' for none): `physics_fault` (NaN
    state; the iteration stopped there and gives no figures), `unsettled` (a settle hit its
    cap with more than the moving fraction of parts still moving), `escaped` (parts left the
    container). The last two are results, flagged; metrics.py counts all three."""
    if row['stop'].startswith(metrics.PHYSICS_FAULT):
        return metrics.PHYSICS_FAULT
    return '+'.join(name for name, bad in ((metrics.UNSETTLED, not row['settled']),
                                           (metrics.ESCAPED, row['escaped'] or row['lost']))
                    if bad)


POSE = ('x', 'y', 'z', 'qx', 'qy', 'qz', 'qw')
GRIPPER_POSE = ('gripper_x', 'gripper_y', 'gripper_z', 'gripper_qx', 'gripper_qy',
                'gripper_qz', 'gripper_qw')


def _key_of(u: Unit) -> tuple[str, int, int]:
    return u.experiment.id, u.group, u.iteration


def _label(u: Unit) -> str:
    kind = u.experiment.type
    if kind == BIN_STATIC:
        return f'bin {u.group + 1}/{len(u.experiment.bins)}, iteration {u.iteration + 1}'
    if kind == TABLE_SWEEP:
        return f'{u.group} parts, iteration {u.iteration + 1}'
    return f'iteration {u.iteration + 1}/{u.experiment.iterations}'
