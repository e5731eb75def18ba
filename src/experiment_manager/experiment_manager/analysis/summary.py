"""summary.json as one typed, versioned model: what a run measured and decided, per experiment.

The metrics (metrics.py, drop_tests.py, sensitivity.py, calibration.py) make each
experiment's record here, typed where it is made, and metrics.file_summary the `Summary`; what
reads a summary (the verdicts, the report, plan, the pictures, redecide) reads its fields. A
run writes `Summary.json_text()` (results.write_summary); `read` is the one way to read a file
back (through `migrate` for files of an older version). Its JSON Schema is published as
docs/summary.schema.json:

    python -m experiment_manager.analysis.summary --schema docs/summary.schema.json

writes it from this module (a test checks that the committed file is current). Units are in
the names (`_mm`, `_s`, `_h`, `_mm2`); shares are fractions of 1. No rclpy.
"""

import json
from typing import Annotated, Literal

from pydantic import ConfigDict, Field

from ..experiment_file.schema import json_schema_text, schema_command
from .migration import migrate, SCHEMA_VERSION
from .records import _Record, Faults, Fractions, Physics, Sampling, Stats, VERDICT


class GumbelFit(_Record):
    n: int
    location_s: float
    scale_s: float
    p: float = Field(description='probability plot correlation p of the fit')
    fits: bool
    k_upper: float
    k_lower: float
    upper: float
    lower: float
    estimate: float


class PaceBound(_Record):
    """The feeder runs' pace when none emptied within the interval (decisions.pace)."""
    picks: int
    cell_h: float
    upper_per_h: float = Field(description='one-sided upper bound of picks per hour, Poisson')
    parts: int = Field(description="a refill's parts")
    emptied_share_at_most: float = Field(description='of refills, within the interval, at '
                                         'that pace')


class FreeBound(_Record):
    verdict: VERDICT
    share_bounds: list[float]   # of the share of runs over the interval, one-sided


class Decision(_Record):
    """One ground of a verdict (decisions.Decision): its quantity bounded one-sidedly."""
    verdict: VERDICT
    quantity: str
    bound: float | None
    interval: str
    runs: int
    reason: str
    # a rate (bins emptied) and the spills
    low: float | None = None
    high: float | None = None
    successes: int | None = None
    spilled: int | None = None
    # the table's time to empty a refill
    over: int | None = None
    censored: int | None = Field(None, description='feeder runs the vibration limit ended with '
                                 'the refill interval unspent: neither within it nor over')
    refill_s: float | None = None
    coverage: float | None = None
    times_s: list[float | None] | None = None
    distribution_free: FreeBound | None = None
    pace: PaceBound | None = None
    gumbel: GumbelFit | None = None


class _Experiment(_Record):
    faults: Faults
    physics: Physics
    sampling: Sampling | None = None
    gripper: str | None = Field(None, description="the gripper of the file's `grippers` it "
                                "ran with; none: the file's own")
    station: bool | None = Field(None, description='with a regrasp station')


class Bin(_Record):
    index: int
    size_mm: list[float]
    xy_area_mm2: float
    iterations: int
    fractions: Fractions
    spilled: Stats


class BinStatic(_Experiment):
    type: Literal['bin_static']
    bins: list[Bin]
    best_bin: int | None
    best_bin_mm: list[float] | None


class BinEmptying(_Experiment):
    type: Literal['bin_emptying']
    iterations: int
    parts: int
    decision: Decision
    bin_mm: list[float] | None
    emptied: int
    emptied_ci95: list[float | None]
    removed: Stats
    searches_per_pick: Stats
    first_check: Fractions
    regrasps: Stats | None = Field(None, description='with a station: picks placed only '
                                   'after a regrasp, per iteration')


class Count(_Record):
    n: int              # parts on the table
    valid: Stats


class TableSweep(_Experiment):
    type: Literal['table_sweep']
    iterations: int
    per_n: list[Count]
    margin: int
    order: int | None = None
    coefficients: list[float] | None = Field(None, description='highest power first')
    n_star: int | None = None
    fit_max: float | None = None
    optimal_range: list[int] | None = None
    no_valid: bool | None = None
    n_star_ci95: list[int] | None = None


class Cell(_Record):
    pick_s: float
    image_s: float
    regrasp_s: float | None = None


class TableGrounds(_Record):
    time: Decision      # the cell's time to empty a refill against the refill interval
    spills: Decision    # parts spilled per refill against requirements.max_spilled_parts


class FeederEmptying(_Experiment):
    type: Literal['feeder_emptying']
    iterations: int
    parts: int
    optimal_range: list[int]
    max_vibrations: int
    emptied: int
    accepted: int
    accepted_ci95: list[float | None]
    max_spilled: int
    runs_spilling: int
    vibrations_to_empty: Stats
    feeds: Stats
    stops: dict[str, int]
    minutes_per_vibration_allowed: float | None
    parts_per_hour: Stats
    parts_per_hour_ci95: list[float | None]
    cell: Cell
    decision: TableGrounds
    first_check: Fractions | None = Field(description="each run's first check, the tray "
                                          'loaded; null in a summary of version 1')
    regrasps: Stats | None = Field(None, description='with a station: picks placed only '
                                   'after a regrasp, per run')


class Variant(_Record):
    index: int
    grasp_set: str
    grasps: list[str]
    gripper_mm: dict[str, float]
    scenes: int
    fractions: Fractions
    valid: Stats
    valid_ci95: list[float | None]
    scenes_with_valid: int
    meets: bool


class GripperSweep(_Experiment):
    type: Literal['gripper_sweep']
    iterations: int
    parts: int
    scene_mm: list[float] | None
    min_valid: float
    variants: list[Variant]
    smallest: int | None


class Held(_Record):
    what: str
    source: str = Field(alias='from')


NUMBER = int | float
ANSWER = NUMBER | str | None    # the best bin is named ('100x175x15'), the others are numbers


class Input(_Record):
    name: str
    base: NUMBER
    low: NUMBER
    high: NUMBER
    source: str


class Said(_Record):
    answers: dict[str, ANSWER]
    verdicts: dict[str, str]


class Scenario(Said):
    name: str
    values: dict[str, NUMBER]


class Flip(_Record):
    scenario: str
    verdict: str | None
    values: dict[str, NUMBER]
    # a table flip its spills make: Fisher's exact p, its runs spilling against the file's
    spills_p: float | None = None


class Robustness(_Record):
    option: str
    verdict: str
    holds: bool
    flips: list[Flip]
    said: str
    line: str
    sources: dict[str, str]


class Axis(_Record):
    input: str
    values: list[NUMBER]


class VerdictMap(_Record):
    rows: Axis
    columns: Axis
    verdicts: dict[str, list[list[str | None]]]


class Point(_Record):
    values: dict[str, float]
    log_likelihood: float


class Calibration(_Record):
    """A drop test's measured counts fitted over a sensitivity's scenarios (calibration.py):
    the likeliest inputs, each one's 95 % interval, the G-test p there, the file keys."""
    experiment: str
    best: dict[str, float]
    intervals: dict[str, list[float]]
    p: float
    points: list[Point]
    keys: list[str]
    # the simulation's noise: SD of a log likelihood difference between two points of one true
    # shares, and how often it alone puts such a point outside the interval
    noise_sd: float | None = Field(description='null in a summary of version 1')
    noise_outside: float | None = Field(description='null in a summary of version 1')


class Sensitivity(_Experiment):
    type: Literal['sensitivity']
    of: list[str]
    iterations: int
    held: dict[str, Held]
    inputs: list[Input]
    base: Said
    scenarios: list[Scenario]
    tornado: dict[str, dict[str, dict[str, ANSWER]]]
    ranges: dict[str, list[ANSWER]]
    robustness: list[Robustness]
    map: VerdictMap | None = None
    calibration: list[Calibration] | None = None


class AspectCount(_Record):
    """An aspect of a drop test: `normal` the unit outward normal, in the part file's frame,
    of the face the part rests on; `difference`: the simulated share less the measured."""
    name: str
    normal: list[float]
    count: int
    share: float | None
    ci95: list[float]
    quasi_static: float
    measured: int | None = None
    measured_share: float | None = None
    difference: float | None = None


class Measured(_Record):
    """A real drop test's counts against the simulated ones: the G-test's p."""
    drops: int
    p: float
    agrees: bool


class DropTest(_Experiment):
    type: Literal['drop_test']
    drops: int
    height_mm: float
    aspects: list[AspectCount]
    other: int
    measured: Measured | None = None


Experiment = Annotated[BinStatic | BinEmptying | TableSweep | FeederEmptying | GripperSweep
                       | DropTest | Sensitivity, Field(discriminator='type')]


class Requirements(_Record):
    parts_per_hour: float
    refill_interval_h: float
    capacity: int
    success_rate: float
    max_dimension_mm: float


class Summary(_Record):
    """summary.json: the file's experiments by id, in the file's order, and a sensitivity
    experiment's repeats of them (`<experiment>@<scenario>`) apart."""
    model_config = ConfigDict(title=f'pick_sim run summary, version {SCHEMA_VERSION}')
    schema_version: Literal[2] = SCHEMA_VERSION
    id: str
    seed: int
    requirements: Requirements
    experiments: dict[str, Experiment]
    repeats: dict[str, Experiment] | None = None

    def of_type(self, kind: str) -> list[tuple[str, _Experiment]]:
        """(id, summary) of the file's experiments of this type, in the file's order."""
        return [(k, v) for k, v in self.experiments.items() if v.type == kind]

    def json_text(self) -> str:
        """summary.json's text: every key the summary was made with, none it left out (a
        record's optional key it was not given stays out, as the published schema allows),
        NaN refused."""
        return json.dumps(self.model_dump(by_alias=True, exclude_unset=True), indent=2,
                          allow_nan=False) + '\n'

    def last(self, kind: str):
        """The file's last experiment of this type (the one a report shows), or None."""
        found = self.of_type(kind)
        return found[-1][1] if found else None


def validate(raw: dict) -> Summary:
    """A summary's dict (current version) as the typed model; pydantic.ValidationError names
    the key path of every key that breaks it."""
    return Summary.model_validate(raw)


def read(path: str) -> Summary:
    """A run directory's summary.json, of any version, as the typed model."""
    with open(path, encoding='utf-8') as f:
        return validate(migrate(json.load(f)))


def schema_text() -> str:
    """The JSON Schema of summary.json, as docs/summary.schema.json holds it."""
    return json_schema_text(Summary)


def main(argv: list[str] | None = None) -> int:
    return schema_command(Summary, 'summary.json', __doc__.split('\n\n')[0], argv)


if __name__ == '__main__':
    raise SystemExit(main())
