"""The records summary.json's experiments share (summary.py builds its model of them): the
base of every record, statistics, stage fractions, faults, physics health and sampling. No
rclpy."""

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

VERDICT = Literal['FEASIBLE', 'NOT FEASIBLE', 'UNDECIDED']


class _Record(BaseModel):
    """A record of summary.json: no key besides its fields, read-only once made."""
    model_config = ConfigDict(extra='forbid', frozen=True, populate_by_name=True)


class Stats(_Record):
    """A list of numbers as metrics.stats says it: None for an empty list."""
    n: int
    mean: float | None
    min: float | None
    max: float | None
    std: float | None = Field(description='sample standard deviation (n - 1); 0 for one value')


class Fractions(_Record):
    """Per iteration, the share of the checked parts that passed each stage."""
    candidates: Stats
    placeable: Stats
    container_free: Stats
    valid: Stats


class Flagged(_Record):
    group: int
    iteration: int
    fault: str = Field(description="procedures.faults' names joined by '+'")
    experiment: str | None = Field(None, description='a sensitivity summary: the repeat')


class Faults(_Record):
    """How many iterations each physics fault flagged; the first three leave an iteration out
    of the figures."""
    physics_fault: int
    tunnelled: int
    thrown: int
    unsettled: int
    flagged: list[Flagged]


class Physics(_Record):
    """The physics health of every iteration, left-out ones too."""
    spilled: int
    tunnelled: int
    thrown: int
    max_speed: float = Field(description='m/s')
    unsettled: int
    max_penetration: float = Field(description='m')
    tray_error: float = Field(description='fraction of the commanded motion')


class Sampling(_Record):
    """An adaptive experiment's sampling (running/sampling.py)."""
    mode: str
    batch: int
    batches: int
    iterations_run: int
    most: int
    settled: bool
    tied_bins: list[int] | None = None
    tie: list[int] | None = None
    tie_within: float | None = None
    race_confidence: float | None = Field(None, description=(  # version 0: 99.9 % intervals
        "one-sided confidence of the bound of a bin's difference from the leader"))
    held: int | None = Field(None, description=(
        'a table_sweep settled because its range starts at or above the parts of every '
        'feeder run that reads it (each puts them all on the table whatever the range): '
        'those parts'))
