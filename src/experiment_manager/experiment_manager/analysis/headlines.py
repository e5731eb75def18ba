"""The headline of each experiment of a run, a line each, as `run` prints them in the terminal
after the run (the report gives the rest)."""

from .calibration import noise_said
from .summary import Summary
from .wording import gripper_label, sampling_end


def headlines(summary: Summary) -> list[str]:
    """A line per experiment of the file (two or more for a sensitivity experiment: one per
    verdict it compared), indented by two spaces, with its sampling when it was adaptive."""
    lines = []
    for exp_id, s in summary.experiments.items():
        kind = s.type
        if kind == 'bin_static':
            lines.append(f'  {exp_id} (bin_static): best bin {s.best_bin_mm} mm')
        elif kind == 'bin_emptying':
            r = s.removed
            lines.append(f'  {exp_id} (bin_emptying): {s.emptied}/{s.iterations} bins '
                         f'emptied, parts removed mean {r.mean:.3g} (min {r.min:g}, '
                         f'max {r.max:g})')
        elif kind == 'table_sweep':
            ci = s.n_star_ci95
            lines.append(f'  {exp_id} (table_sweep): optimum {s.n_star} parts'
                         + (f' (95 % interval {ci[0]}-{ci[1]})' if ci else '')
                         + f', range {s.optimal_range}')
        elif kind == 'gripper_sweep':
            found = s.smallest
            lines.append(f'  {exp_id} (gripper_sweep): ' + (
                f'smallest meeting {s.min_valid:g} valid per check: '
                f'{gripper_label(s.variants[found])}' if found is not None else
                f'no gripper of {len(s.variants)} meets {s.min_valid:g} valid per check'))
        elif kind == 'drop_test':
            lines.append(f'  {exp_id} (drop_test): {s.drops} drops at rest on '
                         + ', '.join(f'{a.name} {100 * (a.share or 0):.1f} %'
                                     for a in s.aspects if a.count)
                         + (f'; against {s.measured.drops} measured: G-test p '
                            f'{s.measured.p:.3g}, '
                            + ('agrees' if s.measured.agrees else 'disagrees')
                            if s.measured is not None else ''))
        elif kind == 'sensitivity':
            lines.append(f'  {exp_id} (sensitivity): {len(s.scenarios)} scenarios over '
                         + ', '.join(x.name for x in s.inputs) + ':')
            lines += [f'    {r.line}' for r in s.robustness]
            for c in s.calibration or ():
                lines.append(f'    calibrated on {c.experiment} (G-test p {c.p:.3g} there); '
                             'the file keys, with 95 % intervals:')
                lines += [f'      {k}' for k in c.keys]
                if said := noise_said(c.noise_sd, c.noise_outside):
                    lines.append(f'    {said}')
        else:
            v = s.vibrations_to_empty.mean
            rate = s.parts_per_hour.mean
            lines.append(f'  {exp_id} (feeder_emptying): {s.emptied}/{s.iterations} '
                         'runs emptied' + (f', {v:.4g} vibrations to empty on average'
                                           if v is not None else '')
                         + (f', {rate:.4g} parts per hour' if rate is not None else ''))
        if s.sampling is not None:
            a = s.sampling
            lines[-1] += (f' [adaptive: {a.iterations_run} of {a.most} iterations, '
                          f'{sampling_end(s)}]')
    return lines
