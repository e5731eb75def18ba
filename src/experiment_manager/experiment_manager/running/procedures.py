"""The four experiment types of the paper (section 4.3) and the gripper sweep as iteration
procedures over a `Backend`: what one iteration does and the rows it records (rows.py has the
columns).

The procedures are the same for every backend, so they are tested without a graph
(LocalBackend), and their rows do not depend on which worker ran them.
"""

import time

from feeder_controller.policy import NAMES as DECISION_NAMES
from feeder_controller.policy import PICK, STOP_EMPTY, STOP_VIBRATION_LIMIT
import numpy as np
from pick_common.errors import PhysicsFault
from pick_common.parts.aspects import classify
from pick_common.states import PartStates, SettleReport
from pick_validity.results import Report, STAGE_NONE

from ..analysis import metrics
from ..analysis.rows import GRIPPER_POSE, POSE, Record
from ..experiment_file import (
    BIN_EMPTYING,
    BIN_STATIC,
    DROP_TEST,
    ExperimentFile,
    FEEDER_EMPTYING,
    GRIPPER_SWEEP,
    GripperVariant,
    TABLE_SWEEP,
)
from ..experiment_file.kinds import kind_of
from ..experiment_file.plan import Unit
from .backend import Backend

MAX_FEED_CYCLES = 1_000_000     # a guard: the vibration limit ends a run long before
NEIGHBOUR_MARGIN = 1.0          # m beyond the container: farther parts are not checked


def search_order(order: str, states: PartStates, targets: np.ndarray, seed: int) -> np.ndarray:
    """The order in which a picking cell would look at the target parts (ids).
    top_first: highest part origin first; id: by id; random: seeded shuffle."""
    if order == 'id':
        return np.sort(targets)
    if order == 'random':
        return np.random.default_rng(seed).permutation(np.sort(targets))
    z = dict(zip(states.ids.tolist(), states.poses[:, 2].tolist(), strict=True))
    return np.array(sorted(targets.tolist(), key=lambda i: (-z[i], i)), dtype=np.int64)


def faults(row: dict) -> str:
    """The physics faults of an iteration, '+'-joined ('' for none): `physics_fault` (NaN
    state; the iteration stopped there), `tunnelled` (a part ended in or under the floor or in
    a wall: solid bodies passed through each other), `thrown` (a part moved faster than
    gravity and the tray can move it: the solver gave it energy), all three of which leave the
    iteration out of the figures; `unsettled` (a settle hit its cap with more than the moving
    fraction of parts still moving), flagged and counted. A spill (a part over a wall) is a
    result, not a fault: its own column. metrics.py counts them."""
    if row['stop'].startswith(metrics.PHYSICS_FAULT):
        return metrics.PHYSICS_FAULT
    return '+'.join(name for name, bad in ((metrics.TUNNELLED, row['tunnelled']),
                                           (metrics.THROWN, row['thrown']),
                                           (metrics.UNSETTLED, not row['settled'])) if bad)


def run_unit(file: ExperimentFile, u: Unit, backend: Backend) -> Record:
    """Run one iteration on `backend`; returns its rows."""
    start = time.monotonic()
    backend.reset(u.container, u.seed)
    iteration = Iteration(file, u, backend)
    try:
        row = PROCEDURES[u.experiment.type](iteration)
    except PhysicsFault as exc:    # its seed would fault again: marked, not run again
        row = {**iteration.health(), 'emptied': False, 'vibrations': 0, 'feeds': 0,
               'stop': f'{metrics.PHYSICS_FAULT}: {exc}'}
    record = iteration.record
    first = record.checks[0] if record.checks else {}
    x, y, z = u.container.inner_size
    record.iteration = {
        'experiment': u.experiment.id, 'type': u.experiment.type, 'group': u.group,
        'iteration': u.iteration, 'seed': u.seed, 'container_x': x, 'container_y': y,
        'container_z': z, 'parts': u.parts,
        **{k: first.get(k, 0) for k in ('checked', 'outside', 'candidates', 'placeable',
                                         'container_free', 'valid')},
        'checks': len(record.checks), 'picks': len(record.picks),
        **row, 'fault': faults(row), 'table_time': iteration.table_time,
        'wall_time': time.monotonic() - start, 'aspect': row.get('aspect', ''),
        'regrasps': sum(p['regrasp'] for p in record.picks)}
    return record


class Iteration:
    """One iteration in progress: the procedures of the five types and the rows they record."""

    def __init__(self, file: ExperimentFile, u: Unit, backend: Backend) -> None:
        self.file, self.u, self.backend = file, u, backend
        self.record = Record(iteration={})
        self.key = {'experiment': u.experiment.id, 'group': u.group, 'iteration': u.iteration}
        self.reports: list[SettleReport] = []
        self.table_time = 0.0   # s the feeder's feeds and vibrations took, simulated

    def health(self) -> dict:
        """The physics of the iteration's world operations so far: whether every settle
        rested, the most parts left moving, parts spilled over a wall, tunnelled and thrown
        (ids counted once), the deepest penetration (m), the fastest part (m/s) and the worst
        tray tracking (fraction)."""
        r = self.reports
        tunnelled = {i for x in r for i in x.tunnelled_ids}
        thrown = {i for x in r for i in x.thrown_ids}
        spilled = {i for x in r for i in x.spilled_ids} - tunnelled - thrown
        return {'settled': all(x.settled for x in r),
                'unsettled': max((len(x.unsettled_ids) for x in r), default=0),
                'spilled': len(spilled), 'tunnelled': len(tunnelled), 'thrown': len(thrown),
                'max_penetration': max((x.max_penetration for x in r), default=0.0),
                'max_speed': max((x.max_speed for x in r), default=0.0),
                'tray_error': max((x.tray.error for x in r if x.tray), default=0.0)}

    def check(self, states: PartStates, neighbours: bool, vibrations: int = 0,
              variant: GripperVariant | None = None) -> tuple[Report | None, np.ndarray]:
        """Check the parts inside the container (with the file's gripper and grasps, or
        `variant`'s); record the check and every part's row. Returns the report (None when no
        part is inside) and the targets in search order."""
        u, record = self.u, self.record
        targets = states.ids[states.inside]
        index = len(record.checks)
        row = {**self.key, 'check': index, 'parts_on_table': int(len(targets)),
               'checked': 0, 'outside': 0, 'candidates': 0, 'placeable': 0,
               'container_free': 0, 'valid': 0,
               'picked_id': -1, 'searches': 0, 'vibrations': vibrations, 'wall_time': 0.0}
        report = None
        stages: dict[int, tuple[int, int, int]] = {}
        if len(targets):
            # Parts that left the container fall for ever (the world has no ground): those
            # NEIGHBOUR_MARGIN beyond it cannot touch a gripper at a part inside; not sent.
            reach = max(u.container.inner_size) + NEIGHBOUR_MARGIN
            near = np.abs(states.poses[:, :3]).max(axis=1) <= reach
            report = self.backend.check(u.container, states.masked(near), targets.tolist(),
                                        neighbours, variant)
            row.update(report.counts)
            row['wall_time'] = report.wall_time
            stages = {r.part_id: (r.stage, r.grasp_index, len(r.valid_tilts))
                      for r in report.results}
        record.checks.append(row)
        for pid, pose, inside in zip(states.ids.tolist(), states.poses.tolist(),
                                     states.inside.tolist(), strict=True):
            stage, grasp, tilts = stages.get(pid, (STAGE_NONE, -1, 0))
            record.parts.append({**self.key, 'check': index, 'part_id': pid,
                                 **dict(zip(POSE, pose, strict=True)), 'inside': inside,
                                 'stage': stage, 'grasp': grasp, 'tilts': tilts})
        order = search_order(self.file.search_order, states, targets, u.seed + index)
        return report, order

    def pick(self, report: Report, order: np.ndarray, vibrations: int = 0) -> int:
        """Choose the first valid part in search order; record the pick. Returns its id."""
        by_id = {r.part_id: r for r in report.results}
        for searches, pid in enumerate(order.tolist(), start=1):
            result = by_id[pid]
            if result.valid:
                check = self.record.checks[-1]
                check['picked_id'], check['searches'] = pid, searches
                self.record.picks.append({
                    **self.key, 'pick': len(self.record.picks), 'check': check['check'],
                    'part_id': pid, 'searches': searches, 'vibrations': vibrations,
                    'grasp': result.grasp_index,
                    **dict(zip(GRIPPER_POSE, np.asarray(result.gripper_pose).tolist(),
                               strict=True)), 'regrasp': int(result.regrasp)})
                return pid
        raise AssertionError('a report with valid parts has none in the search order')

    def static(self) -> dict:
        """bin_static (stages 1-3) and table_sweep (all four stages): drop, settle, check."""
        states, settle = self.backend.drop(self.u.parts, 'container')
        self.reports.append(settle)
        self.check(states, neighbours=kind_of(self.u.experiment).checks_neighbours)
        return {**self.health(), 'emptied': False, 'vibrations': 0, 'feeds': 0, 'stop': ''}

    def drop_test(self) -> dict:
        """drop_test: one part dropped from the plate's drop height, at rest, checked (all four
        stages, as it landed); the aspect it rests on (pick_common.parts.aspects)."""
        states, settle = self.backend.drop(1, 'container')
        self.reports.append(settle)
        self.check(states, neighbours=False)
        inside = states.poses[states.inside]
        aspect = classify(self.file.aspects, inside[:, 3:])[0] if len(inside) else ''
        return {**self.health(), 'emptied': False, 'vibrations': 0, 'feeds': 0, 'stop': '',
                'aspect': aspect}

    def grippers(self) -> dict:
        """gripper_sweep: drop and settle one scene, then check it (all four stages) with each
        gripper and grasp set of the sweep in turn: the iteration's check k is variant k."""
        states, settle = self.backend.drop(self.u.parts, 'container')
        self.reports.append(settle)
        for variant in self.u.experiment.variants:
            self.check(states, neighbours=True, variant=variant)
        return {**self.health(), 'emptied': False, 'vibrations': 0, 'feeds': 0, 'stop': ''}

    def emptying(self) -> dict:
        """bin_emptying: check in search order, remove the first valid part, settle, repeat
        until none is valid or the bin is empty."""
        states, settle = self.backend.drop(self.u.parts, 'container')
        self.reports.append(settle)
        stop = 'empty'
        while states.inside.any():
            report, order = self.check(states, neighbours=True)
            if report.counts['valid'] == 0:
                stop = 'no valid part'
                break
            pid = self.pick(report, order)
            states, settle = self.backend.remove([pid])
            self.reports.append(settle)
        return {**self.health(), 'emptied': not states.inside.any(), 'vibrations': 0,
                'feeds': 0, 'stop': stop}

    def feeder(self) -> dict:
        """feeder_emptying: the feeder loads the table up to max* and vibrates; then after each
        check the policy picks, vibrates, or feeds and vibrates, until it stops."""
        backend = self.backend
        step = backend.feed(0, 0, self.u.feeder)
        self.reports += step.reports
        self.table_time += sum(r.sim_time for r in step.reports)
        states = backend.parts()
        for _ in range(MAX_FEED_CYCLES):
            outside = states.ids[~states.inside].tolist()
            if outside:     # spilled or tunnelled (the reports tell which): off the table
                states, settle = backend.remove(outside, settle=False)
                self.reports.append(settle)
            report, order = self.check(states, neighbours=True, vibrations=step.vibrations)
            valid = report.counts['valid'] if report else 0
            step = backend.feed(valid, int(states.inside.sum()), None)
            self.reports += step.reports
            self.table_time += sum(r.sim_time for r in step.reports)
            if step.decision == PICK:
                pid = self.pick(report, order, step.vibrations)
                states, settle = backend.remove([pid])
                self.reports.append(settle)
            elif step.decision in (STOP_EMPTY, STOP_VIBRATION_LIMIT):
                break
            else:
                states = backend.parts()
        # emptied: the feeder and the table are empty; what spilled is its own figure.
        return {**self.health(), 'emptied': step.decision == STOP_EMPTY,
                'vibrations': step.vibrations, 'feeds': step.feeds,
                'stop': DECISION_NAMES[step.decision]}


# Per kind, what one of its iterations does (a sensitivity has none: its repeats run as the
# experiments they repeat).
PROCEDURES = {BIN_STATIC: Iteration.static, TABLE_SWEEP: Iteration.static,
              BIN_EMPTYING: Iteration.emptying, FEEDER_EMPTYING: Iteration.feeder,
              GRIPPER_SWEEP: Iteration.grippers, DROP_TEST: Iteration.drop_test}
