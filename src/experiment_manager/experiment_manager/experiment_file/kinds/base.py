"""What every experiment kind is (the kinds: this package's modules; the registry: its
__init__): `ExperimentKind`, whose methods a kind overrides where it differs."""

from typing import Any, ClassVar

from feeder_controller.policy import FeederConfig
from pick_common.containers import ContainerSpec

from ..model import Experiment, ExperimentFile, OneContainerExperiment

# The registry, by the file's `type`: filled by the package's __init__ with one instance of
# each kind; read through it (or `kind_of`).
KINDS: dict[str, 'ExperimentKind'] = {}
# One scene an experiment asks for: (group, container, parts on it, the feeder's config or
# None); plan.plan makes its iterations, each with its seed.
Scene = tuple[int, ContainerSpec, int, FeederConfig | None]


class ExperimentKind:
    """One experiment type of the file (its `type`). Its keys are `keys`, a model of
    experiment_keys; `read` turns a checked entry into its `record` (model.py); `groups`,
    `scenes` and `label` plan its iterations. The traits below are what the later rooms
    (analysis, running) read of a kind besides their own tables of it."""

    name: ClassVar[str]
    keys: ClassVar[type]
    record: ClassVar[type[Experiment]]          # what `read` makes (model.py)
    checks_neighbours: ClassVar[bool] = True      # a check asks stage 4 (neighbours)
    left_out_settles: ClassVar[bool] = False      # a left-out iteration decides it
    groups_are_bins: ClassVar[bool] = False       # its groups are bins that race
    uses_checks: ClassVar[bool] = False           # its decision reads checks.csv
    repeats_others: ClassVar[bool] = False        # it runs other experiments again
    own_grippers: ClassVar[bool] = False          # its grippers are its own, not the file's
    feeds: ClassVar[bool] = False                 # the feeder and the table's moves run
    names_aspects: ClassVar[bool] = False         # its rows name the aspect a part rests on
    extends: ClassVar[bool] = False               # it may go on at more counts (plan.extended)

    def read(self, e: Any, where: str, c: Any, out: dict) -> list[Experiment]:
        """The Experiment(s) of the checked entry `e` at `where` (`c`: context.Context; `out`:
        the fields every kind reads, id, iterations, parts, gripper, setup, station,
        seeded_by): one `record`."""
        return [self.record(**out)]

    def groups(self, exp: Experiment) -> list[int]:
        """The groups of its iterations (Unit.group)."""
        return [0]

    def scenes(self, file: ExperimentFile, exp: Experiment, summary: dict) -> list[Scene]:
        """One scene per group, given the summaries of the experiments before it."""
        return [(0, scene_container(file, exp, summary), exp.parts, None)]

    def label(self, exp: Experiment, group: int, iteration: int) -> str:
        """An iteration as a progress line says it."""
        return f'iteration {iteration + 1}/{exp.iterations}'

    def parts(self, exp: Experiment) -> float:
        """The parts of an average iteration (its cost's)."""
        return exp.parts

    def cost_units(self, exp: Experiment, parts: float) -> float:
        """The cost units of one iteration with `parts` parts: its parts."""
        return parts


def kind_of(exp: Experiment) -> ExperimentKind:
    """The kind of an experiment (its `type`'s)."""
    return KINDS[exp.type]


def scene_container(file: ExperimentFile, exp: OneContainerExperiment, summary: dict
                    ) -> ContainerSpec:
    """An experiment's one container: its bin, the best bin of the bin_static it names, or
    the tray when it has neither."""
    if exp.bin_from:
        return file.experiment(exp.bin_from).bins[summary[exp.bin_from].best_bin]
    return file.tray if exp.bin is None else exp.bin
