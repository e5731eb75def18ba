"""The headline of each experiment of a run, a line each, as `run` prints them in the terminal
after the run (the report gives the rest): one function per kind, in HEADLINES by the kind's
name (a table test_kinds.py holds to the registry)."""

from .calibration import noise_said
from .summary import Summary
from .wording import gripper_label, sampling_end


def headlines(summary: Summary) -> list[str]:
    """A line per experiment of the file (two or more for a sensitivity experiment: one per
    verdict it compared), indented by two spaces, with its sampling when it was adaptive."""
    lines = []
    for exp_id, s in summary.experiments.items():
        lines += HEADLINES[s.type](exp_id, s)
        if s.sampling is not None:
            a = s.sampling
            lines[-1] += (f' [adaptive: {a.iterations_run} of {a.most} iterations, '
                          f'{sampling_end(s)}]')
    return lines


def _bin_static(exp_id: str, s) -> list[str]:
    return [f'  {exp_id} (bin_static): best bin {s.best_bin_mm} mm']


def _bin_emptying(exp_id: str, s) -> list[str]:
    r = s.removed
    return [f'  {exp_id} (bin_emptying): {s.emptied}/{s.iterations} bins emptied, parts '
            f'removed mean {r.mean:.3g} (min {r.min:g}, max {r.max:g})']


def _table_sweep(exp_id: str, s) -> list[str]:
    ci = s.n_star_ci95
    return [f'  {exp_id} (table_sweep): optimum {s.n_star} parts'
            + (f' (95 % interval {ci[0]}-{ci[1]})' if ci else '')
            + f', range {s.optimal_range}']


def _gripper_sweep(exp_id: str, s) -> list[str]:
    found = s.smallest
    return [f'  {exp_id} (gripper_sweep): ' + (
        f'smallest meeting {s.min_valid:g} valid per check: '
        f'{gripper_label(s.variants[found])}' if found is not None else
        f'no gripper of {len(s.variants)} meets {s.min_valid:g} valid per check')]


def _drop_test(exp_id: str, s) -> list[str]:
    return [f'  {exp_id} (drop_test): {s.drops} drops at rest on '
            + ', '.join(f'{a.name} {100 * (a.share or 0):.1f} %' for a in s.aspects if a.count)
            + (f'; against {s.measured.drops} measured: G-test p {s.measured.p:.3g}, '
               + ('agrees' if s.measured.agrees else 'disagrees')
               if s.measured is not None else '')]


def _sensitivity(exp_id: str, s) -> list[str]:
    lines = [f'  {exp_id} (sensitivity): {len(s.scenarios)} scenarios over '
             + ', '.join(x.name for x in s.inputs) + ':']
    lines += [f'    {r.line}' for r in s.robustness]
    for c in s.calibration or ():
        lines.append(f'    calibrated on {c.experiment} (G-test p {c.p:.3g} there); '
                     'the file keys, with 95 % intervals:')
        lines += [f'      {k}' for k in c.keys]
        if said := noise_said(c.noise_sd, c.noise_outside):
            lines.append(f'    {said}')
    return lines


def _feeder_emptying(exp_id: str, s) -> list[str]:
    v = s.vibrations_to_empty.mean
    rate = s.parts_per_hour.mean
    return [f'  {exp_id} (feeder_emptying): {s.emptied}/{s.iterations} runs emptied'
            + (f', {v:.4g} vibrations to empty on average' if v is not None else '')
            + (f', {rate:.4g} parts per hour' if rate is not None else '')]


HEADLINES = {'bin_static': _bin_static, 'bin_emptying': _bin_emptying,
             'table_sweep': _table_sweep, 'feeder_emptying': _feeder_emptying,
             'gripper_sweep': _gripper_sweep, 'drop_test': _drop_test,
             'sensitivity': _sensitivity}
