"""How far a run's answers and verdicts move with the inputs nobody can measure before the
hardware is bought: a sensitivity experiment's summary.

A sensitivity experiment repeats experiments of the file in scenarios (experiment_file/
scenarios.py: each input at its low and its high, the others at the file's values, and jointly
in a Latin hypercube). Its summary puts side by side, per scenario, the headline answers
(`ANSWERS`: the best bin, n* and the valid parts per check there, the cell's time to empty a
refill and the vibrations it took, the parts removed per bin) and the verdicts (verdicts.py,
on the scenario's repeats standing in for the experiments they repeat; only the options
whose deciding experiment is repeated: the static bin's bin_emptying, the table's
feeder_emptying, a gripper_sweep); per input, each
answer at its low and its high against the file's values (a tornado chart's bars,
report/plots.py); and per option whether its verdict holds in every scenario or which scenarios
flip it, with the inputs' values there.

Pure: no rclpy, no files.
"""

from dataclasses import dataclass

from scipy.stats import fisher_exact

from ..experiment_file import Ran, SensitivityExperiment
from ..experiment_file.kinds import kind_of
from ..experiment_file.scenarios import grid_levels, point_key
from . import calibration, metrics
from . import summary as model
from .decisions import combined
from .records import Faults, Physics
from .verdicts import NOT_ANALYSED, UNDECIDED, verdicts
from .wording import fmt

# answer -> (its words, its unit)
ANSWERS = {
    'best_bin': ('best bin', 'mm'),
    'n_star': ('n*', 'parts'),
    'valid_at_n_star': ('valid parts per check at n*', 'parts'),
    'time_to_empty': ("cell's time to empty a refill, 90 % bound", 'min'),
    'vibrations': ('vibrations to empty the feeder, mean', ''),
    'removed': ('parts removed per bin, mean', 'parts'),
    'bins_emptied': ('bins emptied', 'share'),
}


def answers(experiments: dict) -> dict:
    """The headline answers of one scenario's experiments (id -> summary, as the file names
    them): those its experiments give, the last of each type."""
    out = {}
    last = {s.type: s for s in experiments.values()}
    if (s := last.get('bin_static')) and s.best_bin_mm:
        out['best_bin'] = 'x'.join(fmt(v) for v in s.best_bin_mm)
    if (s := last.get('table_sweep')) and s.n_star is not None:
        out['n_star'] = s.n_star
        near = min(s.per_n, key=lambda p: abs(p.n - s.n_star), default=None)
        if near is not None:
            out['valid_at_n_star'] = near.valid.mean
    if s := last.get('feeder_emptying'):
        bound = s.decision.time.bound
        out['time_to_empty'] = None if bound is None else bound / 60.0
        out['vibrations'] = s.vibrations_to_empty.mean
    if s := last.get('bin_emptying'):
        out['removed'] = s.removed.mean
        out['bins_emptied'] = s.emptied / s.iterations if s.iterations else None
    return out


def summarise(file: Ran, exp: SensitivityExperiment,
              summaries: dict) -> model.Sensitivity:
    """The sensitivity experiment `exp`'s summary from every experiment's (`summaries`, by
    id; its repeats among them)."""
    base = {k: v for k, v in summaries.items()
            if '@' not in k and not kind_of(file.experiment(k)).repeats_others}

    def view(scenario: str | None) -> dict:
        swapped = dict(base)
        if scenario is not None:
            swapped.update({e: summaries[f'{e}@{scenario}'] for e in exp.of})
        return swapped

    # the options whose deciding experiment is repeated (an option whose runs are the file's
    # in every scenario would hold over all ranges without having been tried on them)
    last = {v.type: k for k, v in base.items()}
    moved = ({'static bin'} if last.get('bin_emptying') in exp.of else set()) | (
        {'vibrating table'} if last.get('feeder_emptying') in exp.of else set()) | {
        f'gripper (`{e}`)' for e in exp.of if kind_of(file.experiment(e)).own_grippers}

    def said(experiments: dict) -> dict:
        # the answers of the experiments repeated (the others' do not move), and the verdicts
        verdicts_now = verdicts(metrics.file_summary(file, experiments))
        return {'answers': answers({e: experiments[e] for e in exp.of}),
                'verdicts': {v.kind: v.verdict for v in verdicts_now
                             if v.verdict != NOT_ANALYSED and v.kind in moved}}

    base_said = model.Said(**said(view(None)))
    scenarios = [model.Scenario(name=sc.name, values=dict(sc.values), **said(view(sc.name)))
                 for sc in exp.scenarios]
    # the table's spill and time grounds per scenario (None: the file's), when it is repeated
    table = last.get('feeder_emptying')
    spill_runs = ({name: _spill_runs(view(name)[table])
                   for name in [None, *(sc.name for sc in exp.scenarios)]}
                  if table in exp.of else {})
    by_name = {s.name: s for s in scenarios}
    tornado = {}
    for key in ANSWERS:
        if key not in base_said.answers or key == 'best_bin':
            continue
        # an end at the file's value was not run again (scenarios.scenarios): the file's
        tornado[key] = {x.name: {end: by_name.get(f'{_stem(x.name)}_{end}', base_said)
                                 .answers.get(key) for end in ('low', 'high')}
                        for x in exp.inputs}
    repeats = {f'{e}@{sc.name}': summaries[f'{e}@{sc.name}'] for sc in exp.scenarios
               for e in exp.of}
    # a repeat whose bin or range comes from an experiment not repeated ran at the file's
    held = {e: model.Held(what=what, source=source) for e in exp.of for what in ('range', 'bin')
            if (source := file.experiment(e).taken_from.get(f'{what}_from'))
            and source not in exp.of}
    grid = _map(exp, base_said, scenarios)
    fitted = _calibrations(file, exp, base, summaries)
    return model.Sensitivity(
        type=exp.type, of=list(exp.of), iterations=exp.iterations, held=held,
        inputs=[model.Input(name=x.name, base=x.base, low=x.low, high=x.high, source=x.source)
                for x in exp.inputs],
        base=base_said, scenarios=scenarios, tornado=tornado,
        ranges=_ranges(base_said, scenarios),
        robustness=_held_said(_robustness(exp, base_said, scenarios, spill_runs), held),
        **({'map': grid} if grid else {}), **({'calibration': fitted} if fitted else {}),
        faults=_faults(repeats), physics=_physics(repeats))


def _calibrations(file: Ran, exp: SensitivityExperiment, base: dict, summaries: dict
                  ) -> list[model.Calibration]:
    """Each repeated drop test with measured counts fitted over the scenarios (and the
    file's own values): calibration.calibrate."""
    out = []
    for e in exp.of:
        if not kind_of(file.experiment(e)).names_aspects or not file.experiment(e).measured:
            continue
        measured = dict(file.experiment(e).measured)
        points = [({x.name: x.base for x in exp.inputs}, calibration.counts_of(base[e]))]
        points += [({**{x.name: x.base for x in exp.inputs}, **dict(sc.values)},
                    calibration.counts_of(summaries[f'{e}@{sc.name}'])) for sc in exp.scenarios]
        out.append(calibration.calibrate(e, measured, points))
    return out


def _map(exp: SensitivityExperiment, base: model.Said, scenarios: list[model.Scenario]
         ) -> model.VerdictMap | None:
    """With two inputs on a grid: each option's verdict at each pair of their levels (rows the
    first input's, columns the second's), a map over them; None otherwise. A grid point that
    was not run on its own takes the answers of the scenario (or the file) with its inputs
    (scenarios.scenarios leaves such points out)."""
    if not exp.grid or len(exp.inputs) != 2:
        return None
    first, second = exp.inputs
    by_point = {point_key(exp.inputs, s.values): s.verdicts for s in scenarios}
    by_point.setdefault(point_key(exp.inputs, {}), base.verdicts)
    rows, columns = grid_levels(first, exp.grid), grid_levels(second, exp.grid)
    at = {(r, c): by_point[point_key(exp.inputs, {first.name: r, second.name: c})]
          for r in rows for c in columns}
    return model.VerdictMap(
        rows=model.Axis(input=first.name, values=rows),
        columns=model.Axis(input=second.name, values=columns),
        verdicts={o: [[at[(r, c)].get(o) for c in columns] for r in rows]
                  for o in base.verdicts})


def _held_said(robustness: list[model.Robustness], held: dict[str, model.Held]
               ) -> list[model.Robustness]:
    """A flip's words end with what was not repeated and so ran at the file's (a range or bin
    chosen for the file's inputs may be why it flips)."""
    if not held:
        return robustness
    words = '; '.join(f'`{e}` at the {h.what} of `{h.source}`, not repeated'
                      for e, h in held.items())
    return [r.model_copy(update={'said': f'{r.said} ({words})', 'line': f'{r.line} ({words})'})
            if r.flips else r for r in robustness]


def _stem(name: str) -> str:
    return name.replace('.', '_')


def _ranges(base: model.Said, scenarios: list[model.Scenario]) -> dict:
    """Per answer, the values over the base and every scenario: numbers as [min, max],
    the best bin as the bins named."""
    out = {}
    for key in ANSWERS:
        values = [s.answers.get(key) for s in [base, *scenarios]]
        values = [v for v in values if v is not None]
        if not values:
            continue
        out[key] = sorted(set(values)) if key == 'best_bin' else [min(values), max(values)]
    return out


@dataclass(frozen=True)
class SpillRuns:
    """A feeder_emptying summary's runs, those that spilled, the parts a run may spill
    (`limit`) and its two grounds' verdicts."""
    runs: int
    spilling: int
    limit: int
    spills: str
    time: str


def _spill_runs(feeder: model.FeederEmptying) -> SpillRuns:
    grounds = feeder.decision
    return SpillRuns(feeder.iterations, feeder.runs_spilling, feeder.max_spilled,
                     grounds.spills.verdict, grounds.time.verdict)


def _spills_p(here: SpillRuns, there: SpillRuns, verdict: str) -> float | None:
    """For a table's flip to `verdict` made by its spills (`here` the scenario's _spill_runs,
    `there` the file's: the file's time ground with the scenario's spills gives `verdict`):
    Fisher's exact p (two-sided) that its runs spilling and the file's are one rate; None for
    a flip its spills do not make, or where a run may spill parts (requirements.
    max_spilled_parts above 0: the ground then counts the runs spilling more than that, which
    `runs_spilling`, the runs spilling any, is not)."""
    if (there.limit or here.spills == there.spills
            or combined([there.time, here.spills]) != verdict):
        return None
    return _one_rate_p(here.spilling, here.runs, there.spilling, there.runs)


def _one_rate_p(k: int, n: int, j: int, m: int) -> float:
    """Fisher's exact p (two-sided) that k of n and j of m are draws of one rate."""
    return float(fisher_exact([[k, n - k], [j, m - j]]).pvalue)


def _robustness(exp: SensitivityExperiment, base: model.Said, scenarios: list[model.Scenario],
                spill_runs: dict | None = None) -> list[model.Robustness]:
    """Per option of the base verdicts: whether it holds in every scenario, and where not,
    the scenarios that flip it (their verdict and their inputs' values; for the table, a
    flip its spills make with `spills_p`, _spills_p, and its words say which such flips
    so few runs do not tell from the file's), with a line for the terminal."""
    inputs = {x.name: x for x in exp.inputs}
    out = []
    for option, verdict in base.verdicts.items():
        flips = []
        for s in scenarios:
            there = s.verdicts.get(option)
            if there == verdict:
                continue
            p = (_spills_p(spill_runs[s.name], spill_runs[None], there)
                 if option == 'vibrating table' and spill_runs else None)
            flips.append(model.Flip(scenario=s.name, verdict=there, values=s.values,
                                    **({'spills_p': p} if p is not None else {})))
        if not flips:
            said = (f'{verdict} over all ranges ({len(scenarios)} scenarios: '
                    + ', '.join(inputs) + ')')
        else:
            where = []
            for f in flips:
                values = ', '.join(f'{k} {fmt(v, 4)}' for k, v in f.values.items())
                where.append(f'{f.verdict} at {values}')
            said = (f'{verdict} here, but ' + '; '.join(where)
                    + f' ({len(flips)} of {len(scenarios)} scenarios)')
            if all(f.verdict == UNDECIDED for f in flips):
                said += ': the runs there do not settle it, which is not a flip to the other side'
            said += _drawn(flips, spill_runs)
        out.append(model.Robustness(
            option=option, verdict=verdict, holds=not flips, flips=flips, said=said,
            line=f'{option} {said}',
            sources={k: inputs[k].source for f in flips for k in f.values}))
    return out


def _drawn(flips: list[model.Flip], spill_runs: dict | None) -> str:
    """Words for the flips their spills make whose runs do not tell them from the file's
    (Fisher's exact p at least 0.05): how many, their runs spilling beside the file's, and
    whether any count of runs this few could have (the smallest p they allow)."""
    drawn = [f for f in flips if (f.spills_p or 0.0) >= 0.05]
    if not drawn:
        return ''
    base = spill_runs[None]
    runs = [spill_runs[f.scenario] for f in drawn]
    counts = sorted({(r.spilling, r.runs) for r in runs})
    ps = sorted({round(f.spills_p, 2) for f in drawn})
    # the smallest p any count allows: all runs spilling on one side, none on the other
    least = max(_one_rate_p(r.runs, r.runs, 0, base.runs) for r in runs)
    return (f'. {len(drawn)} of these flip on their spills, with runs spilling '
            + ', '.join(f'{k} of {n}' for k, n in counts)
            + f" there against {base.spilling} of {base.runs} at the file's values, "
            "which so few runs do not tell apart (Fisher's exact p "
            + ' to '.join(f'{p:.2f}' for p in sorted({ps[0], ps[-1]}))
            + (f'; no count of so few runs could: the least p they allow is {least:.2f}'
               if least >= 0.05 else '')
            + "): more runs would tell the draw's from the input's")


def _faults(repeats: dict) -> Faults:
    """The repeats' fault counts, added (metrics.fault_counts' fields), and their flagged
    iterations."""
    return Faults(**{k: sum(getattr(r.faults, k) for r in repeats.values())
                     for k in metrics.FAULTS},
                  flagged=[f.model_copy(update={'experiment': exp_id})
                           for exp_id, r in repeats.items() for f in r.faults.flagged])


def _physics(repeats: dict) -> Physics:
    """The repeats' physics health (metrics.physics' fields): totals and worsts."""
    total = ('spilled', 'tunnelled', 'thrown')
    none = metrics.physics([])      # the health of no iteration: every count 0
    values = {k: [getattr(r.physics, k) for r in repeats.values()] for k in Physics.model_fields}
    return Physics(**{k: sum(v) if k in total else max(v, default=getattr(none, k))
                      for k, v in values.items()})
