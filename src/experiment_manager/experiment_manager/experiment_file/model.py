"""What a run uses of an experiment file, in SI units: the frozen dataclasses the loader
(`loading`) builds from the file as written (`schema`), and the names and limits both share."""

from dataclasses import dataclass, field, replace
import math
from typing import ClassVar

from pick_common.containers import ContainerSpec
from pick_common.parts.spec import PartSpec
from pick_common.specs import Vibration
from pick_validity.config import CheckConfig, PlaceSpec, Setup
from pick_validity.grippers import GripperKind

BIN_STATIC, BIN_EMPTYING, TABLE_SWEEP, FEEDER_EMPTYING, GRIPPER_SWEEP, SENSITIVITY = (
    'bin_static', 'bin_emptying', 'table_sweep', 'feeder_emptying', 'gripper_sweep',
    'sensitivity')
DROP_TEST = 'drop_test'
TYPES = (BIN_STATIC, BIN_EMPTYING, TABLE_SWEEP, FEEDER_EMPTYING, GRIPPER_SWEEP, DROP_TEST,
         SENSITIVITY)
SEARCH_ORDERS = ('top_first', 'random', 'id')
FIXED, ADAPTIVE = 'fixed', 'adaptive'
SAMPLING_MODES = (FIXED, ADAPTIVE)
MAX_ITERATIONS = 10_000
MAX_BINS = 100
MAX_EXPERIMENTS = 50
MAX_VARIANTS = 64         # grippers x grasp sets of one gripper_sweep
MAX_FILE_BYTES = 1_000_000
ID_CHARS = set('abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-')
MM, G, DEG = 1e-3, 1e-3, math.pi / 180.0   # the file's mm, g and degrees in SI
DROP_PLATE = 12.0           # a drop test's plate, across, in part radii (a bounce stays on it)


@dataclass(frozen=True)
class Requirements:
    """The production requirement: parts of this type per hour, hours between refills of a bin
    or the feeder, the largest bin length in any dimension, m, the parts a feeder run may
    spill over the tray's walls (a cell catches none by default: a spilled part is lost), and
    the share of bins and of feeder runs that must succeed (empty, within the spill limit),
    which a verdict needs at 95 % confidence (analysis/verdicts.py). 0.9: the highest share that the
    paper's fixed counts can show when every iteration succeeds (40 bins: 95 % interval from
    0.912; 50 runs: from 0.929; 36 iterations are the fewest that reach 0.9)."""

    parts_per_hour: float = 60.0
    refill_interval: float = 4.0 * 3600.0      # s
    max_dimension: float = 0.3                 # m
    max_spilled: int = 0                       # parts per feeder run
    success_rate: float = 0.9                  # share of bins / feeder runs

    @property
    def capacity(self) -> int:
        """Parts a bin or feeder must hold to last one refill interval."""
        return math.ceil(self.parts_per_hour * self.refill_interval / 3600.0)


@dataclass(frozen=True)
class Cell:
    """The picking cell's own times, for its throughput (analysis/metrics.py): the robot's
    pick-and-place cycle per part, s, and the vision system's image per check (after every
    pick and every vibration), s. The table's time comes from the simulation: each feed's and
    vibration's simulated duration until the parts rest. 4 s per pick: the fast end of the 4
    to 10 s a hand insertion of a wired part takes (docs/decisions.md); 0 s per image: not
    counted unless set. Set both to the cell's measured figures. A regrasp on a station
    costs one more place and pick, regrasp_time s: assumed as long as a pick."""

    pick_time: float = 4.0      # s
    image_time: float = 0.0     # s
    regrasp_time: float = 4.0   # s


@dataclass(frozen=True)
class Sampling:
    """How many iterations an experiment runs. fixed: its `iterations` (per bin or count), as
    the paper's counts. adaptive: batches of `batch` iterations per group until its decision
    is settled (running/sampling.py), at most its `iterations`."""

    mode: str = FIXED
    batch: int = 5

    @property
    def adaptive(self) -> bool:
        return self.mode == ADAPTIVE


@dataclass(frozen=True)
class GripperVariant:
    """One gripper and grasp set of a gripper_sweep: the gripper, the name of the grasp set
    (a key of the experiment's `grasp_sets`) and its grasps, in part.grasps order."""

    gripper: GripperKind
    grasp_set: str
    grasps: tuple

    @property
    def size(self) -> tuple[float, ...]:
        """What "smaller" means when grippers are compared: its kind's (grippers.py)."""
        return self.gripper.size


@dataclass(frozen=True)
class Input:
    """One uncertain input of a sensitivity experiment: its name (a key of
    scenarios.INPUTS), the file's value and the range to try, in the file's units, and where
    the range comes from (said with every answer that moves with it)."""

    name: str
    base: float
    low: float
    high: float
    source: str


@dataclass(frozen=True)
class Scenario:
    """One sensitivity scenario: its name and its inputs' values (name -> value, file units).
    What they make (the part, gripper and table moves) is its repeats' `setup` and `moves`."""

    name: str
    values: tuple[tuple[str, float], ...]


@dataclass(frozen=True, kw_only=True)
class Experiment:
    """One experiment of the file: what every kind has. Each kind's record below adds its
    own fields (its kind in kinds/ builds it, `kinds.base.ExperimentKind.record`); `type` is
    the record's, not an argument.

    parts: the parts of a scene. gripper: the gripper of the file's `grippers` it runs with
    ('' and None: the file's own); setup: the setup it runs with (None: the file's; a named
    gripper's, a scenario's); moves: the table's moves it runs with (None: the file's; a
    scenario's); station: with a regrasp station (its setup's check says so); seeded_by: the
    experiment whose seeds it runs on (scenes_of; '': its own); scenario: the sensitivity
    scenario a repeat (`<id>@<scenario>`) runs in.
    """

    type: ClassVar[str]
    id: str
    iterations: int
    parts: int = 0
    gripper: str = ''
    setup: Setup | None = None
    moves: tuple[Vibration, ...] | None = None
    station: bool = False
    seeded_by: str = ''
    scenario: Scenario | None = None

    @property
    def taken_from(self) -> dict[str, str]:
        """Its fields that name an earlier experiment it takes something from (bin_from: that
        one's best bin; range_from: its optimal range), each with the id it names."""
        return {}

    @property
    def sources(self) -> tuple[str, ...]:
        """The experiments whose summaries this one needs before it is planned."""
        return tuple(self.taken_from.values())


@dataclass(frozen=True, kw_only=True)
class BinStaticExperiment(Experiment):
    """bin_static: its candidate bins."""

    type: ClassVar[str] = BIN_STATIC
    bins: tuple[ContainerSpec, ...] = ()


@dataclass(frozen=True, kw_only=True)
class OneContainerExperiment(Experiment):
    """A kind whose scenes are in one container: `bin`, or the best bin of the bin_static
    `bin_from` names, or (neither) the tray (kinds.base.scene_container)."""

    bin: ContainerSpec | None = None
    bin_from: str = ''

    @property
    def taken_from(self) -> dict[str, str]:
        return {'bin_from': self.bin_from} if self.bin_from else {}


@dataclass(frozen=True, kw_only=True)
class BinEmptyingExperiment(OneContainerExperiment):
    """bin_emptying: one bin picked until no part is valid."""

    type: ClassVar[str] = BIN_EMPTYING


@dataclass(frozen=True, kw_only=True)
class TableSweepExperiment(OneContainerExperiment):
    """table_sweep: counts, the parts on the tray per group; margin, the counts a sweep may
    go on beyond its last while its fit still rises (extend)."""

    type: ClassVar[str] = TABLE_SWEEP
    counts: tuple[int, ...] = ()
    margin: int = 5
    extend: bool = True


@dataclass(frozen=True, kw_only=True)
class FeederEmptyingExperiment(OneContainerExperiment):
    """feeder_emptying: its [min*, max*], or None when `range_from` names the table_sweep
    whose optimum is used; the feeder's limits on vibrations and one feed's parts."""

    type: ClassVar[str] = FEEDER_EMPTYING
    optimal_range: tuple[int, int] | None = None
    range_from: str = ''
    max_vibrations: int = 500
    max_feed: int = 0

    @property
    def taken_from(self) -> dict[str, str]:
        return {**super().taken_from, **({'range_from': self.range_from} if self.range_from
                                         else {})}


@dataclass(frozen=True, kw_only=True)
class GripperSweepExperiment(OneContainerExperiment):
    """gripper_sweep: its grippers and grasp sets, checked on the same scenes; min_valid:
    the valid parts per check a gripper must give (its 95 % interval's low end at least
    this)."""

    type: ClassVar[str] = GRIPPER_SWEEP
    variants: tuple[GripperVariant, ...] = ()
    min_valid: float = 1.0


@dataclass(frozen=True, kw_only=True)
class DropTestExperiment(OneContainerExperiment):
    """drop_test: its plate is its `bin`; measured: the user's counts per aspect name."""

    type: ClassVar[str] = DROP_TEST
    measured: tuple[tuple[str, int], ...] = ()


@dataclass(frozen=True, kw_only=True)
class SensitivityExperiment(Experiment):
    """sensitivity: the experiments repeated (`of`), the uncertain inputs, the scenarios and
    the grid levels per input (0: no grid)."""

    type: ClassVar[str] = SENSITIVITY
    of: tuple[str, ...] = ()
    inputs: tuple[Input, ...] = ()
    scenarios: tuple[Scenario, ...] = ()
    grid: int = 0

    @property
    def sources(self) -> tuple[str, ...]:
        return tuple(f'{e}@{s.name}' for s in self.scenarios for e in self.of)


@dataclass(frozen=True)
class Ran:
    """What deciding a run reads of the file it ran with: its id and seed, the requirements
    and the cell's times, the aspects the part rests on, and its experiments in the file's
    order. A run's metrics get it from the file (`ExperimentFile.ran`); `decide` from the
    run's resolved.json (experiment_file.resolved.ran), with no file read again and no part
    built: there its experiments' setups and moves are not kept (None), and a gripper_sweep
    variant's grasps are as written."""

    id: str
    seed: int
    requirements: Requirements
    cell: Cell
    aspects: tuple
    experiments: tuple[Experiment, ...]

    def experiment(self, experiment_id: str) -> Experiment:
        return next(e for e in self.experiments if e.id == experiment_id)


@dataclass(frozen=True)
class ExperimentFile:
    """Everything a run needs, in SI units. `path` is the file read; `text` its content."""

    id: str
    seed: int
    output_dir: str
    setup: Setup            # the part, gripper, grasps, placing and check settings, packed once
    search_order: str
    tray: ContainerSpec
    moves: tuple[Vibration, ...]
    bin_wall: float
    requirements: Requirements
    experiments: tuple[Experiment, ...]
    sampling: Sampling = Sampling()
    cell: Cell = Cell()
    path: str = ''
    text: str = field(default='', repr=False)
    auto_grasps: bool = False   # the grasps were proposed from the geometry (part.grasps: auto)
    part_volume: float = 0.0    # m^3, the part's (the packing rule of a sweep's extra counts)
    # per contact pair, how each value was got and where they come from (part.material_account)
    material_account: tuple[tuple[str, tuple[tuple[str, str], ...], str], ...] = ()
    # the aspects the part can rest on (pick_common.parts.aspects), from the geometry the
    # file was checked with: what a drop test classifies by and counts
    aspects: tuple = field(default=(), compare=False, repr=False)
    given: frozenset[str] = frozenset()     # the file's top keys it sets (the rest: defaults)

    def experiment(self, experiment_id: str) -> Experiment:
        return next(e for e in self.experiments if e.id == experiment_id)

    @property
    def ran(self) -> Ran:
        """What deciding a run of this file reads of it."""
        return Ran(self.id, self.seed, self.requirements, self.cell, self.aspects,
                   self.experiments)

    def first_of(self, kind: str) -> Experiment | None:
        """The file's first experiment of this type (the one a picture shows), or None."""
        return next((e for e in self.experiments if e.type == kind), None)

    @property
    def part(self) -> PartSpec:
        return self.setup.part

    @property
    def gripper(self) -> GripperKind:
        return self.setup.gripper

    @property
    def grasps(self) -> tuple:
        return self.setup.grasps

    @property
    def place(self) -> PlaceSpec:
        return self.setup.place

    @property
    def check(self) -> CheckConfig:
        return self.setup.config

    def for_experiment(self, exp: Experiment) -> 'ExperimentFile':
        """The file an experiment's iterations run with: this one, or this one with the setup
        and moves the experiment runs with (a named gripper's; a sensitivity scenario's)."""
        changed = {k: v for k, v in (('setup', exp.setup), ('moves', exp.moves))
                   if v is not None}
        return replace(self, **changed) if changed else self

    def variant_setup(self, variant: GripperVariant | None) -> Setup:
        """The setup a check runs with: the file's, or a gripper_sweep variant's gripper and
        grasps in it."""
        if variant is None:
            return self.setup
        return replace(self.setup, gripper=variant.gripper, grasps=variant.grasps)
