"""The cores in this process: a `World`, a `Validator` and a `FeederPolicy`, no ROS graph.

The same physics and checks as the nodes, one call away instead of one message away: the tests of
the experiment logic and the benchmark's graph-against-core ratio run on it.
"""

from feeder_controller.policy import FeederConfig, FeederPolicy
from pick_common.containers import ContainerSpec
from pick_common.specs import SceneSpec
from pick_common.states import PartStates, SettleReport
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World
from pick_validity.results import Report
from pick_validity.validity import Validator

from ..experiment_file import ExperimentFile, GripperVariant
from .backend import FeedStep


class LocalBackend:
    """Implements backend.Backend with the cores. Call close() (or use `with`)."""

    def __init__(self, physics: PhysicsConfig | None = None) -> None:
        self._physics = physics
        self._world: World | None = None
        self._validator: Validator | None = None
        self._variants: dict[GripperVariant, Validator] = {}
        self._policy: FeederPolicy | None = None
        self._file: ExperimentFile | None = None

    def start(self, file: ExperimentFile) -> None:
        self._file = file
        self._world = self._world or World(SceneSpec(file.tray, file.part), self._physics)
        self._validator = Validator(file.setup, self._world.part)
        self._variants = {}

    def reset(self, container: ContainerSpec, seed: int) -> None:
        self._world.reset(SceneSpec(container, self._file.part, 1, seed))

    def drop(self, count: int, zone: str) -> tuple[PartStates, SettleReport]:
        _, report = self._world.drop(count, zone=zone)
        return self._world.snapshot(), report

    def remove(self, ids: list[int], settle: bool = True) -> tuple[PartStates, SettleReport]:
        _, report = self._world.remove(ids, settle=settle)
        return self._world.snapshot(), report

    def parts(self) -> PartStates:
        return self._world.snapshot()

    def check(self, container: ContainerSpec, states: PartStates, targets: list[int],
              neighbours: bool, variant: GripperVariant | None = None) -> Report:
        validator = self._validator
        if variant is not None:
            validator = self._variants.get(variant)
            if validator is None:
                validator = self._variants[variant] = Validator(
                    self._file.variant_setup(variant), self._world.part)
        return validator.check(container, states.ids.tolist(), states.poses, targets,
                               neighbours)

    def feed(self, valid: int, on_table: int, restart: FeederConfig | None) -> FeedStep:
        if restart is not None:
            self._policy = FeederPolicy(restart)
        policy = self._policy
        step = policy.decide(valid, on_table)
        reports = []
        fed = 0
        if step.feed:       # the hopper may let out fewer than the dose (hopper.py)
            ids, report = self._world.drop(step.feed, zone='feeder')
            reports.append(report)
            if fed := len(ids):
                policy.fed(fed)
        if step.vibrates:
            reports += [self._world.vibrate(move) for move in self._file.moves]
            policy.vibrated()
        s = policy.state
        return FeedStep(step.decision, fed, s.vibrations, s.feeds, s.in_feeder,
                        tuple(reports))

    def rejoin(self, stop) -> bool:
        """Cores in this process do not come back once lost."""
        return False

    def close(self) -> None:
        if self._world is not None:
            self._world.close()
            self._world = None

    def __enter__(self) -> 'LocalBackend':
        return self

    def __exit__(self, *exc) -> None:
        self.close()
