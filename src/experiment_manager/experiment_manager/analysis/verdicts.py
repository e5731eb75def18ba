"""The decisions of a run: a verdict per option (static bin, vibrating table) with its reasons,
and, for the paper's test-case files, the paper's findings checked on the run (against_paper).
Rendering them is report/'s job.

Verdicts, per option, each resting on what its runs measure, bounded one-sidedly where the
requirement is one-sided (decisions.py; the bounds are computed with the metrics, metrics.py,
and kept in summary.json as each experiment's `decision`):
- static bin: the share of `bin_emptying` iterations that emptied the bin, against
  requirements.success_rate (one-sided 95 % exact bounds); and the bin must hold a refill
  interval's parts (requirements.parts_per_hour x refill_interval_h);
- vibrating table, on two grounds: the cell's time to empty a refill (picks, images, the
  table's simulated feeds and vibrations; a run that did not empty is over) against the
  refill interval, for requirements.success_rate of refills at 95 % confidence (a one-sided
  tolerance bound, Gumbel, with a distribution-free one beside it); and the share of
  refills spilling at most requirements.max_spilled_parts parts against the same
  success_rate, on its one-sided exact bounds; the feeder must hold a refill interval's
  parts. FEASIBLE when every ground is, NOT FEASIBLE when one is, else UNDECIDED, saying
  which grounds are settled;
- gripper (one per gripper_sweep): the smallest gripper of the sweep whose valid parts per
  check reach the experiment's min_valid at 95 % confidence; not feasible when every
  gripper's interval lies below min_valid.
A sensitivity experiment adds to each option's reasons whether its verdict holds over the
inputs' ranges or which scenarios flip it (sensitivity.py).
Iterations left out of the figures (a NaN state, a tunnelled or a thrown part) make no option
feasible.
An option whose experiment did not run is "not analysed".
"""

from dataclasses import dataclass, field

import numpy as np

from . import decisions
from .metrics import EXCLUDED, FAULTS
from .summary import Decision, GripperSweep, Summary, Variant
from .wording import count, dims, fmt, gripper_label, pct, table

# The paper's results (section 5) for its test case, by experiment-file id.
PAPER = {
    'pth0': {'best_bin_mm': [100, 175, 15], 'container_free': 0.2502, 'valid_first': 0.0036,
             'table2': {'iterations': 40, 'parts': 240, 'emptied': 0, 'mean': 0.8, 'min': 0,
                        'max': 4, 'std': 0.92},
             'n_star': 49, 'range': [44, 54],
             'table3': {'iterations': 50, 'parts': 240, 'emptied': 50, 'vibrations': 123.14}},
    'pth1': {'best_bin_mm': [300, 300, 26], 'container_free': 0.3477, 'valid_first': 0.0047,
             'table2': {'iterations': 40, 'parts': 480, 'emptied': 0, 'mean': 2.7, 'min': 0,
                        'max': 6, 'std': 1.67},
             'n_star': 22, 'range': [17, 27],
             'table3': {'iterations': 50, 'parts': 480, 'emptied': 50, 'vibrations': 166.96}},
    'pth2': {'best_bin_mm': [300, 300, 22], 'container_free': 0.388, 'valid_first': 0.0127,
             'table2': {'iterations': 40, 'parts': 480, 'emptied': 0, 'mean': 7.5, 'min': 2,
                        'max': 11, 'std': 2.28},
             'n_star': 27, 'range': [22, 32],
             'table3': {'iterations': 50, 'parts': 480, 'emptied': 50, 'vibrations': 139.07}},
}
DIFFERS = 1.25     # a figure differs from the paper's when ours is over 1.25x or under 0.8x it
FALLS = 0.05       # past n*, the sweep's fit "falls" when it ends at least 5 % below its peak
FEASIBLE, NOT_FEASIBLE, UNDECIDED, NOT_ANALYSED = ('FEASIBLE', 'NOT FEASIBLE', 'UNDECIDED',
                                                  'not analysed')
# the feeder policy's stop decisions (feeder_controller.policy.NAMES), as a report says them
_STOPS = {'stop: empty': 'feeder and table empty', 'stop: vibration limit': 'vibration limit'}


@dataclass
class Verdict:
    """An option's decision: `option` as people read it ('static bin 100 x 175 x 15 mm'),
    `kind` as scenarios compare it ('static bin' whichever bin was best, a gripper sweep's by
    its experiment, 'gripper (`id`)', whichever gripper was smallest), the verdict, the reasons
    (the first decides), and the grounds it rests on, by name."""
    option: str
    kind: str
    verdict: str
    reasons: list[str]
    grounds: dict[str, Decision] = field(default_factory=dict)
    stops: str = ''         # the stage that stops most checked parts, and its share


def verdicts(summary: Summary) -> list[Verdict]:
    """The decision per option, in the order static bin, vibrating table, gripper sweeps;
    the bin and the table once per gripper their experiments ran with (the file's first, then
    its `grippers` in the order the experiments name them)."""
    capacity = summary.requirements.capacity
    required = summary.requirements.success_rate
    out = [_bin_verdict(s, option, capacity, required)
           for option, s in _per_gripper(summary, 'bin_emptying')] or [
        Verdict('static bin', 'static bin', NOT_ANALYSED,
                ['no bin_emptying experiment in the file'])]
    out += [_table_verdict(s, option, capacity, required)
            for option, s in _per_gripper(summary, 'feeder_emptying')] or [
        Verdict('vibrating table', 'vibrating table', NOT_ANALYSED,
                ['no feeder_emptying experiment in the file'])]
    out += [_gripper_verdict(exp_id, s) for exp_id, s in summary.of_type('gripper_sweep')]
    for exp_id, s in summary.of_type('sensitivity'):     # how far each verdict moves
        lines = {r.option: r.said for r in s.robustness}
        for v in out:
            if v.kind in lines:
                v.reasons.append(f'over the ranges of `{exp_id}`: {lines[v.kind]}')
    return out


def _per_gripper(summary: Summary, kind: str) -> list[tuple[tuple[str, bool], object]]:
    """((gripper name, '' for the file's own; with a station), the last experiment of `kind`
    run so), the file's own gripper first, without a station before with one."""
    found: dict[tuple[str, bool], object] = {}
    for _, s in summary.of_type(kind):
        found[s.gripper or '', bool(s.station)] = s
    return sorted(found.items(), key=lambda item: (item[0][0] != '', item[0][1]))


def _named(text: str, option: tuple[str, bool]) -> str:
    gripper, station = option
    return (text + (' with a regrasp station' if station else '')
            + (f', gripper {gripper}' if gripper else ''))


def stops_most(fractions) -> tuple[str, float] | None:
    """The stage that stops the largest share of the checked parts (from a check's stage
    fractions) and that share, or None without figures."""
    f = [fractions.candidates.mean, fractions.placeable.mean, fractions.container_free.mean,
         fractions.valid.mean]
    if any(v is None for v in f):
        return None
    lost = {'candidacy': 1.0 - f[0], 'placeability': f[0] - f[1], 'container': f[1] - f[2],
            'neighbours': f[2] - f[3]}
    stage = max(lost, key=lost.get)
    return stage, lost[stage]


def _stops(fractions) -> str:
    found = stops_most(fractions) if fractions is not None else None
    return '' if found is None else f'{found[0]} ({pct(found[1])} of the parts checked)'


def _bin_verdict(s, option: tuple[str, bool], capacity: int, required: float) -> Verdict:
    decision = s.decision
    reasons = [decision.reason + _more(decision, required),
               f'parts removed per bin: mean {fmt(s.removed.mean)}, max '
               f'{fmt(s.removed.max)} of {s.parts}']
    if s.regrasps is not None and s.regrasps.mean is not None:
        reasons.append(f'of them placed after a regrasp on the station: mean '
                       f'{fmt(s.regrasps.mean)} per bin')
    verdict, reasons = _decided(decision.verdict, reasons, s,
                                None if s.parts >= capacity else
                                f'the bin was filled with {s.parts} parts, fewer than '
                                f'the {capacity} a refill interval needs')
    return Verdict(_named(f'static bin {dims(s.bin_mm)} mm', option),
                   _named('static bin', option), verdict, reasons, {'emptied': decision},
                   _stops(s.first_check))


def _table_verdict(s, option: tuple[str, bool], capacity: int, required: float) -> Verdict:
    grounds = {'time': s.decision.time, 'spills': s.decision.spills}
    time, spills = grounds['time'], grounds['spills']
    verdict = decisions.combined([g.verdict for g in grounds.values()])
    settled = [f'{name} {g.verdict}' for name, g in grounds.items() if g.verdict != UNDECIDED]
    open_ = [name for name, g in grounds.items() if g.verdict == UNDECIDED]
    v = s.vibrations_to_empty
    # the ground that decides first (run prints only the first reason): NOT FEASIBLE,
    # then UNDECIDED, then FEASIBLE; the time first among equals
    said = sorted([(time, time.reason + _more(time, required)),
                   (spills, spills.reason + _more(spills, required))],
                  key=lambda g: [NOT_FEASIBLE, UNDECIDED, FEASIBLE].index(g[0].verdict))
    reasons = [said[0][1], said[1][1],
               'grounds settled: ' + (', '.join(settled) or 'none')
               + ('; not settled: ' + ', '.join(open_) if open_ else ''),
               f'{s.emptied} of {s.iterations} feeder runs emptied '
               f'(optimal range {s.optimal_range[0]}-{s.optimal_range[1]} parts on '
               f'the table; runs ended by: '
               f'{", ".join(f"{_STOPS.get(k, k)} {n}" for k, n in s.stops.items())})']
    if v.mean is not None:
        reasons.append(f'vibrations to empty the feeder: mean {fmt(v.mean, 4)}; the '
                       f'refill interval allows one vibration every '
                       f'{fmt(s.minutes_per_vibration_allowed)} min')
    if s.parts_per_hour.mean is not None:
        reasons.append(f'the cell would pick {fmt(s.parts_per_hour.mean, 4)} parts per hour '
                       f'on average, at {fmt(s.cell.pick_s)} s per pick and '
                       f'{fmt(s.cell.image_s)} s per image (cell.pick_s, '
                       'cell.image_s) and the simulated time of the feeds and vibrations'
                       + (f', and {fmt(s.cell.regrasp_s)} s per regrasp (cell.regrasp_s; '
                          f'{fmt(s.regrasps.mean)} per run)' if s.regrasps is not None
                          and s.regrasps.mean is not None else ''))
    verdict, reasons = _decided(verdict, reasons, s, None if s.parts >= capacity else
                                f'the feeder held {s.parts} parts, fewer than the '
                                f'{capacity} a refill interval needs')
    return Verdict(_named('vibrating table', option), _named('vibrating table', option),
                   verdict, reasons, grounds, _stops(s.first_check))


def _decided(verdict: str, reasons: list[str], s, shortfall: str | None
             ) -> tuple[str, list[str]]:
    """An option's verdict and reasons after what decides it whatever its rate says: a
    container that cannot hold a refill interval's parts (`shortfall`, its sentence) and
    iterations left out of the figures make it NOT FEASIBLE, and their reasons come first (run
    prints only the first); other flagged iterations are said last."""
    faults, left_out = _fault_reason(s), _left_out(s)
    first = ([shortfall] if shortfall else []) + (faults if left_out else [])
    if shortfall or left_out:
        verdict = NOT_FEASIBLE
    return verdict, first + reasons + ([] if left_out else faults)


def _more(decision: Decision, required: float) -> str:
    """For an unsettled ground, what would settle it."""
    if decision.verdict != UNDECIDED:
        return ''
    if decision.successes is not None:         # a rate
        more = decisions.iterations_to_decide(decision.successes, decision.runs, required)
        return ('; not settled: ' + (f'{more} iterations would settle it if the rate seen held'
                                     if more else 'no number of iterations would at the rate '
                                     'seen, which is the requirement itself'))
    if decision.censored:
        return ('; not settled: runs at this vibration limit cannot settle it; with a higher '
                "max_vibrations (the experiment's; the ground says how high) a run empties or "
                'outlasts the interval')
    if decision.runs < 3:
        return '; not settled: 3 runs give the fitted bound'
    return '; not settled: more runs narrow the bound (run --adaptive runs until it is settled)'


def _gripper_verdict(exp_id: str, s: GripperSweep) -> Verdict:
    """A gripper_sweep's answer: the smallest gripper whose valid parts per check reach
    min_valid at 95 % confidence, or that none of the sweep does."""
    variants = s.variants
    where = (f'{len(variants)} grippers x grasp sets checked on the same {s.iterations} '
             f'scenes of {s.parts} parts in the {dims(s.scene_mm)} mm container')
    kind = f'gripper (`{exp_id}`)'
    if s.smallest is None:
        best = max(variants, key=lambda v: v.valid.mean or 0.0)
        # not feasible only where every gripper's interval lies below min_valid
        open_ = [v for v in variants if v.valid_ci95[1] is None
                 or v.valid_ci95[1] >= s.min_valid]
        option, verdict = kind, UNDECIDED if open_ else NOT_FEASIBLE
        reasons = [f'no gripper of the sweep gives {fmt(s.min_valid)} valid parts per check '
                   f'at 95 % confidence; the most: {gripper_label(best)}, mean '
                   f'{fmt(best.valid.mean)} (95 % interval {interval_text(best)})']
        if open_:
            reasons.append(f'not enough scenes to decide: {count(len(open_), "gripper")} of '
                           f'the sweep had an interval reaching {fmt(s.min_valid)}, or too '
                           'few scenes for one')
    else:
        v = variants[s.smallest]
        option, verdict = f'gripper {gripper_label(v)} (`{exp_id}`)', FEASIBLE
        reasons = [f'the smallest of the sweep whose valid parts per check reach '
                   f'{fmt(s.min_valid)} at 95 % confidence: mean '
                   f'{fmt(v.valid.mean)}, 95 % interval {interval_text(v)}; '
                   f'{v.scenes_with_valid} of {v.scenes} scenes had a valid part']
    verdict, reasons = _decided(verdict, reasons + [where], s, None)
    return Verdict(option, kind, verdict, reasons)


def shown_interval(v: Variant) -> tuple[float | None, float | None]:
    """A gripper_sweep variant's 95 % interval of valid parts per check as the report shows it
    (text and plot): from 0 where the Student-t interval reaches below (two scenes of 4 valid
    parts each gave -14 to 22; a count is never negative). summary.json keeps the interval as
    computed, and `meets` is decided on it."""
    low, high = v.valid_ci95
    return (None, None) if low is None else (max(low, 0.0), high)


def interval_text(v: Variant) -> str:
    """shown_interval, as the report's sentences and tables say it."""
    low, high = shown_interval(v)
    return '-' if low is None else f'{fmt(low)} to {fmt(high)}'


def _left_out(s) -> bool:
    """Whether iterations were left out of the figures (a NaN state, a tunnelled or a thrown
    part)."""
    return any(getattr(s.faults, k) for k in EXCLUDED)


def _fault_reason(s) -> list[str]:
    """The flagged iterations, in words. Caller: an option is not feasible when any iteration
    was left out (its figures are missing)."""
    f = s.faults
    if not f.flagged:
        return []
    return [f'{count(len(f.flagged), "iteration")} flagged: ' + ', '.join(
        f'{k} {getattr(f, k)}' for k in FAULTS if getattr(f, k))
        + ' (see Physics health)']


def _ratio(ours, paper) -> str:
    return '-' if ours is None or not paper else f'{ours / paper:.2f}'


def _differs(ours, paper) -> bool:
    return ours is not None and bool(paper) and not 1 / DIFFERS <= ours / paper <= DIFFERS


def _sweep_shape(s) -> tuple[str, bool]:
    """How valid parts go with the parts on the tray (the fit), and whether that is the
    paper's shape: up to a peak inside the sweep, then down by at least FALLS."""
    last = s.per_n[-1].n
    if s.no_valid:
        return 'no valid part at any count: the gripper cannot pick this part off the table', False
    if s.n_star >= last:
        return f"still rising at the sweep's last count, n = {last}", False
    fall = 1 - float(np.polyval(s.coefficients, last)) / s.fit_max
    shape = 'then fall' if fall >= FALLS else 'then level off'
    return (f'rise to n* = {s.n_star}, {shape}: {100 * fall:.0f} % below the peak at '
            f'n = {last} (fit)'), fall >= FALLS


def against_paper(summary: Summary, paper: dict) -> list[str]:
    """The paper's three findings and its figures beside this run's, and where and why ours
    differ. The reasons are what we know differs between the two set-ups, not measured causes."""
    findings, figures, differ = [], [], set()
    e, b, w, f = (summary.last(kind) for kind in (
        'bin_emptying', 'bin_static', 'table_sweep', 'feeder_emptying'))
    t2, t3 = paper['table2'], paper['table3']
    if b and b.best_bin is not None:
        best = b.bins[b.best_bin]
        free = best.fractions.container_free.mean
        same = [float(x) for x in paper['best_bin_mm']] == [float(x) for x in b.best_bin_mm]
        figures += [['best bin (mm)', dims(b.best_bin_mm),
                     dims(paper['best_bin_mm']),
                     'the same' if same else 'another'],
                    ['its parts free of the bin (bin collision free)', pct(free),
                     pct(paper['container_free']), _ratio(free, paper['container_free'])]]
        if not same or _differs(free, paper['container_free']):
            differ.add('bins')
    if e:
        agrees = e.emptied == 0
        findings.append([f'static bins never emptied ({t2["emptied"]} of {t2["iterations"]})',
                         f'{e.emptied} of {e.iterations} emptied',
                         'agrees' if agrees else 'differs'])
        ours_valid, ours_removed = e.first_check.valid.mean, e.removed.mean
        figures += [['valid at the first check of a full bin', pct(ours_valid),
                     pct(paper['valid_first']), _ratio(ours_valid, paper['valid_first'])],
                    ['parts removed per bin (mean)', fmt(ours_removed), fmt(t2['mean']),
                     _ratio(ours_removed, t2['mean'])]]
        if not agrees or _differs(ours_valid, paper['valid_first']) \
                or _differs(ours_removed, t2['mean']):
            differ.add('bins')
    if w and w.n_star is not None:
        shape, agrees = _sweep_shape(w)
        findings.append([f'valid parts rise with the parts on the tray, then fall (n* = '
                         f'{paper["n_star"]})', shape, 'agrees' if agrees else 'differs'])
        figures.append(['parts on the table at the optimum, n*', w.n_star, paper['n_star'],
                        _ratio(w.n_star, paper['n_star'])])
        if not agrees or _differs(w.n_star, paper['n_star']):
            differ.add('table')
    if f:
        agrees = f.iterations > 0 and f.emptied == f.iterations
        findings.append([f'the tray emptied in every feeder run ({t3["emptied"]} of '
                         f'{t3["iterations"]})', f'{f.emptied} of {f.iterations} emptied',
                         'agrees' if agrees else 'differs'])
        vib = f.vibrations_to_empty.mean
        figures.append(['vibrations to empty the feeder (mean)', fmt(vib, 4),
                        fmt(t3['vibrations'], 4), _ratio(vib, t3['vibrations'])])
        if not agrees or _differs(vib, t3['vibrations']):
            differ.add('feeder')
    lines = ['', '## Against the paper', '']
    lines += table(['the paper found', 'this run', 'agrees?'], findings) + ['']
    lines += table(['figure', 'ours', 'the paper', 'ours / paper'], figures)
    why = {
        'bins': "Static bins: our part models stand in for the paper's figure 13 and the "
                'gripper is ours (the paper gives the dimensions of neither; see the part '
                'table of docs/paper-test-case.md). Which parts a grasp can reach free of the '
                'walls and of their neighbours, and so the parts removed, follow from both.',
        'table': 'Table optimum: n* counts parts of our models on the tray, each with the '
                 'clearance our gripper needs: both are ours.',
        'feeder': "Feeder: the table's motion is a model of ours (the paper does not say how "
                  'its table moves); the vibrations to empty the feeder follow from it and from '
                  'the load, n* above.'}
    lines += ['', f'A figure differs when ours is over {DIFFERS:g} times or under '
              f"{1 / DIFFERS:g} times the paper's."
              + (' Where this run differs, and why:' if differ else ' None does.')]
    lines += [f'- {why[k]}' for k in ('bins', 'table', 'feeder') if k in differ]
    if f and f.physics.spilled:
        lines.append(f'- {count(f.physics.spilled, "part")} spilled over the tray\'s '
                     f'walls, in {f.runs_spilling} of {f.iterations} feeder runs; a run '
                     f'may spill {f.max_spilled}.')
    lines += ['', 'No setting of the simulation was tuned to agree with the paper.']
    return lines
