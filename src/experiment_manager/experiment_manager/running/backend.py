"""What an experiment needs from the physics and the checks: the `Backend` protocol, and what
its calls return beyond the shared core types.

Two implementations: `LocalBackend` (local_backend.py) runs the cores in this process;
`GraphBackend` (graph_backend.py) calls a worker's `world`, `validity` and `feeder_controller`
nodes. The experiments are the same for both.
"""

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from feeder_controller.policy import FeederConfig
from pick_common.containers import ContainerSpec
from pick_common.states import PartStates, SettleReport
from pick_validity.results import Report

from ..experiment_file import ExperimentFile, GripperVariant


@dataclass(frozen=True)
class FeedStep:
    """What one feed_cycle did: the decision (feeder_controller.policy constants), parts fed,
    the feeder's counts afterwards, and the world's reports of its feed and vibration."""

    decision: int
    fed: int
    vibrations: int
    feeds: int
    in_feeder: int
    reports: tuple[SettleReport, ...] = ()


class WorkerLost(Exception):
    """A backend's worker died or stopped answering: its iteration in flight is run again on
    another worker, and this worker gets more only if it comes back (Backend.rejoin)."""


class Backend(Protocol):
    """What an experiment needs done. Raises pick_common.errors.PickError subclasses for bad
    input and physics faults, WorkerLost (a graph backend) when its worker is gone."""

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
              neighbours: bool, variant: GripperVariant | None = None) -> Report:
        """The staged checks of `targets` among every part of `states`, with the file's
        gripper and grasps or, given a variant (gripper_sweep), its own."""

    def feed(self, valid: int, on_table: int, restart: FeederConfig | None) -> FeedStep:
        """One feeder policy step (restart: load the feeder first)."""

    def rejoin(self, stop: Callable[[], bool]) -> bool:
        """After WorkerLost: wait for the worker to come back; False if it does not (in the
        backend's own time) or once stop() holds."""
