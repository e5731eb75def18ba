"""An experiment's summary from its rows (`summarise`: the one step the scheduler takes when an
experiment's last iteration is written, and `redecide` for each experiment of a finished run),
and a finished run decided again with today's rules: every experiment's summary computed anew
from the run's own result files (iterations.csv, picks.csv, checks.csv) and what it ran with
(its resolved.json's records, experiment_file.resolved.ran: no experiment file read again, no
part built), in the file's order. What a rule cannot recompute is kept from the run's
summary.json: an adaptive experiment's sampling (the batches it took are the run's history).
Results written before a rule changed (the table's bound, the bins' race) are then read as
today's. No rclpy."""

from dataclasses import replace
import os

from ..experiment_file import Experiment, Ran, resolved
from ..experiment_file.kinds import kind_of
from . import metrics, sensitivity
from . import summary as summary_model
from .records import Sampling
from .results import read_csv


def redecide(run_dir: str, recorded: summary_model.Summary | None = None
             ) -> summary_model.Summary:
    """The summary (current version) of the run in `run_dir` as today's
    metrics and decisions give it; `recorded`: the run's summary.json when the caller has read
    it (read here otherwise, when there is one). Raises InvalidArgument when a run directory
    with no records in its resolved.json has an experiment.yaml that no longer reads,
    ValueError for broken records, OSError when a result file is missing."""
    file = resolved.ran(run_dir)
    rows, picks, checks = (read_csv(os.path.join(run_dir, f'{name}.csv'))
                           for name in ('iterations', 'picks', 'checks'))
    path = os.path.join(run_dir, 'summary.json')
    if recorded is None and os.path.exists(path):
        recorded = summary_model.read(path)
    sampled = _sampling(recorded) if recorded is not None else {}
    summaries: dict[str, summary_model.Experiment] = {}
    for exp in file.experiments:
        mine = [r for r in rows if r['experiment'] == exp.id]
        reached = (all(s in summaries for s in exp.sources) if kind_of(exp).repeats_others
                   else bool(mine))
        if not reached:         # an interrupted run stopped before it
            continue
        exp = as_run(exp, mine)
        summaries[exp.id] = summarise(
            file, exp, mine, [p for p in picks if p['experiment'] == exp.id],
            [c for c in checks if c['experiment'] == exp.id], summaries)
        if exp.id in sampled:
            summaries[exp.id] = summaries[exp.id].model_copy(
                update={'sampling': sampled[exp.id]})
    return metrics.file_summary(file, summaries)


def as_run(exp: Experiment, rows: list[dict]) -> Experiment:
    """`exp` as the run ran it: a table_sweep the run extended to more counts than the file
    gives (plan.extended; the run's records keep the file's) with those counts, found in its
    rows."""
    if not kind_of(exp).extends:
        return exp
    more = sorted({r['group'] for r in rows} - set(exp.counts))
    return replace(exp, counts=exp.counts + tuple(more)) if more else exp


def summarise(file: Ran, exp: Experiment, rows: list[dict], picks: list[dict],
              checks: list[dict], earlier: dict) -> summary_model.Experiment:
    """An experiment's summary from its rows of iterations.csv, picks.csv and checks.csv, and
    the summaries of the experiments before it (`earlier`): a sensitivity's from its repeats'
    (sensitivity.summarise), every other kind's from its rows (metrics.summarise)."""
    if kind_of(exp).repeats_others:
        return sensitivity.summarise(file, exp, earlier)
    return metrics.summarise(file, exp, rows, picks, earlier, checks)


def _sampling(recorded: summary_model.Summary) -> dict[str, Sampling]:
    """Each adaptive experiment's sampling as the run's summary recorded it, by id."""
    every = {**recorded.experiments, **(recorded.repeats or {})}
    return {k: s.sampling for k, s in every.items() if s.sampling is not None}
