"""The report of a run: the decision the engineer came for, with the figures behind it.

From a run directory (`summary.json`, read by summary.read; `resolved.json`, what the run ran
with: experiment_file.resolved; `pictures.json`, the pictures of analysis/pictures.py when they were
rendered; `part.json`, the part's account of part_sheet.py; `checks.csv`) it writes `report.md`
and `report.html` (the same content) and the figures of `plots`. The report is its sections
(SECTIONS, one module each on `base.Section`), in order; tables follow the paper's Tables 2
and 3, and for its test-case files (ids pth0, pth1, pth2) its figures stand beside ours. The
decisions themselves are verdicts.py's; this package renders them. No rclpy.
"""

import json
import os

from ...experiment_file import resolved
from .. import stages
from .. import summary as summary_model
from ..results import read_csv
from .base import Run, Section
from .bins import BinEmptying, StaticBins
from .drop_tests import DropTests
from .grippers import Grippers
from .health import Health
from .page import to_html, VERDICT_CLASS
from .paper import AgainstPaper
from .part import Part
from .pictures import Pictures, TurnedDown
from .plots import draw_all, plot_tornado, tornado_bars
from .sampling import Sampling
from .sensitivity import Sensitivity
from .table import Feeder, FEEDING, Sweep
from .verdict import Head

SECTIONS: tuple[Section, ...] = (Head(), Part(), Sampling(), StaticBins(), BinEmptying(),
                                 Sweep(), Feeder(), Grippers(), DropTests(), Sensitivity(),
                                 AgainstPaper(),
                                 Health(), Pictures(), TurnedDown())

__all__ = ['markdown', 'plot_tornado', 'Run', 'SECTIONS', 'to_html', 'tornado_bars',
           'VERDICT_CLASS', 'write']


def markdown(run: Run) -> str:
    """The report as Markdown: every section's lines, in order."""
    return '\n'.join(line for section in SECTIONS for line in section.lines(run)) + '\n'


def _json(path: str):
    if not os.path.exists(path):
        return None
    with open(path, encoding='utf-8') as f:
        return json.load(f)


def read(run_dir: str) -> Run:
    """A run directory as the report reads it (base.Run), its figures not yet drawn: what the
    run ran with from its resolved.json (experiment_file.resolved.read: for a run directory
    made before runs wrote one, its experiment.yaml resolved by today's rules)."""
    ran = resolved.read(run_dir)
    checks = os.path.join(run_dir, 'checks.csv')
    gripper = dict(ran['gripper'])
    return Run(summary=summary_model.read(os.path.join(run_dir, 'summary.json')),
               part_model=ran['part']['model'], part_dimensions_mm=ran['part']['dimensions_mm'],
               gripper_type=gripper.pop('type'), gripper=gripper,
               pictures=_json(os.path.join(run_dir, 'pictures.json')),
               account=_json(os.path.join(run_dir, 'part.json')),
               stops=stages.turned_down(read_csv(checks)) if os.path.exists(checks) else None,
               tray=ran['tray'], unset=tuple(k for k in FEEDING if k in ran['defaulted']),
               max_feed=ran['doses'])


def write(run_dir: str) -> str:
    """Write the report of a run directory; returns the path of report.html."""
    run = read(run_dir)
    run.figures = draw_all(run.summary, lambda name: os.path.join(run_dir, name))
    run.figures['aspects'] = os.path.exists(os.path.join(run_dir, 'aspects.png'))
    text = markdown(run)
    with open(os.path.join(run_dir, 'report.md'), 'w', encoding='utf-8') as f:
        f.write(text)
    path = os.path.join(run_dir, 'report.html')
    with open(path, 'w', encoding='utf-8') as f:
        f.write(to_html(text, f'Picking feasibility: {run.summary.id}'))
    return path
