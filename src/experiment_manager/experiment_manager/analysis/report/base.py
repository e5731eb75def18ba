"""What every section of the report shares: the run as the sections read it (`Run`), and the
base of a section (`Section`): a heading, and the Markdown lines under it, or none when the run
has nothing for it."""

from dataclasses import dataclass, field
from functools import cached_property

from ...experiment_file.schema import Part as PartKeys
from ..summary import Summary
from ..verdicts import PAPER, Verdict, verdicts


@dataclass
class Run:
    """A finished run as the report reads it, what it ran with from its resolved.json
    (experiment_file.resolved). summary: summary.json; part_model and part_dimensions_mm: the
    part's model and the dimensions it was built with (mm); gripper_type and gripper: the
    gripper's kind and every key of it, in the file's units; figures: which plots were drawn,
    by name (plots.py); pictures: {image file: caption} (pictures.py); account: the part's
    account (part_sheet.describe), with its sheet `part.png`; stops: why parts were turned
    down, per experiment (stages.turned_down); tray: the tray it ran on (resolved.json's
    `tray`: its size, walls, feeder zone and hopper lip, mm), None when unknown; unset: those
    of the tray's keys the file left to their defaults; max_feed: each feeder run's dose, by
    experiment id (0: the whole shortfall at once)."""
    summary: Summary
    part_model: str = PartKeys.model_fields['model'].default
    part_dimensions_mm: dict[str, float] = field(default_factory=dict)
    gripper_type: str = 'jaws'
    gripper: dict[str, float] = field(default_factory=dict)
    figures: dict[str, bool] = field(default_factory=dict)
    pictures: dict[str, str] | None = None
    account: list[str] | None = None
    stops: dict[str, dict[str, int]] | None = None
    tray: dict | None = None
    unset: tuple[str, ...] = ()
    max_feed: dict[str, int] = field(default_factory=dict)

    @property
    def paper(self) -> dict | None:
        """The paper's figures when the file is one of its test case's (verdicts.PAPER)."""
        return PAPER.get(self.summary.id)

    @cached_property
    def verdicts(self) -> list[Verdict]:
        return verdicts(self.summary)


class Section:
    """A part of the report: `lines(run)`, its Markdown (a heading and what is under it, after
    a blank line), [] when the run has nothing for it."""

    def lines(self, run: Run) -> list[str]:
        raise NotImplementedError
