"""The `experiment_manager` executable: its node's module run with the stopping signals held
from the first instruction (pick_common.interrupts.start), so that a signal that comes while
it still imports stops it cleanly."""

from pick_common import interrupts


def main() -> None:
    interrupts.start('experiment_manager.graph.experiment_manager_node')
