"""The vibrating table: the sweep of parts on the tray (the paper's figure 15: the fit, n* and
its optimal range, with warnings where the range is not pinned down) and the feeder emptying
(its Table 3, and the parts per hour the cell would pick)."""


from ..wording import count, fmt, table
from .base import Run, Section


class Sweep(Section):
    def lines(self, run: Run) -> list[str]:
        found = run.summary.of_type('table_sweep')
        if not found:
            return []
        exp_id, s = found[-1]
        paper = run.paper
        lines = ['', f'## Vibrating table sweep (`{exp_id}`, figure 15)', '']
        if run.figures.get('fig15'):
            lines += ['![figure 15](fig15_table.png)', '']
        if s.no_valid:
            lines += ['**No valid part at any count**: with this gripper and these grasps no '
                      'part on the table can be picked and placed, so n* and its range say '
                      'nothing (the feeder runs use them all the same, and cannot empty the '
                      'table).', '']
        if s.n_star is None:
            return lines
        ci = s.n_star_ci95
        low, high = s.optimal_range
        lines += [f'Fit of order {s.order}: the most valid parts at n* = {s.n_star} '
                  f'parts on the table' + (f' (95 % interval {ci[0]}-{ci[1]}, bootstrap)'
                                           if ci else '') +
                  f'; optimal range {low}-{high}' + (
                      f' (paper: n* = {paper["n_star"]}, {paper["range"][0]}-'
                      f'{paper["range"][1]}).' if paper else '.')]
        if ci and (ci[0] < low or ci[1] > high):
            lines += ['', f'**Note**: the interval of n* reaches beyond the optimal '
                      f'range: these drops do not pin n* down to it, and others of the same '
                      f'parts could put it anywhere in {ci[0]}-{ci[1]}. Compare the valid '
                      f'parts per check across that span (figure 15) before relying on '
                      f'the range.']
        tested = [p.n for p in s.per_n]
        if tested and high > max(tested):
            lines += ['', f'**Warning**: the optimal range runs past the last count tested '
                      f'({max(tested)} parts): beyond it the fit is an extrapolation'
                      + (', and n* sits at that count, so the fit is still rising there: the '
                         'sweep goes on at more counts by itself until its peak lies inside '
                         'them, so the tray holds no more (its packing limit) or the file says '
                         '`extend: false`' if s.n_star >= max(tested) else '') + '.']
        return lines


class Feeder(Section):
    def lines(self, run: Run) -> list[str]:
        found = run.summary.of_type('feeder_emptying')
        if not found:
            return []
        exp_id, s = found[-1]
        paper = run.paper
        lines = ['', f'## Feeder emptying (`{exp_id}`, Table 3)', '']
        rows = [['ours', s.iterations, s.parts, f'{s.optimal_range[0]}-{s.optimal_range[1]}',
                 s.emptied, s.vibrations_to_empty.mean]]
        if paper:
            t = paper['table3']
            rows.append(['paper', t['iterations'], t['parts'],
                         f'{paper["range"][0]}-{paper["range"][1]}', t['emptied'],
                         t['vibrations']])
        lines += table(['', 'iterations', 'parts', 'optimal range', 'emptied',
                        'av. vibrations to empty'], rows)
        if run.tray is not None:
            lines += ['', feeding(run.tray, run.max_feed.get(exp_id, 0), run.unset)]
        per_refill = s.physics.spilled / s.iterations if s.iterations else 0.0
        hourly = run.summary.requirements.parts_per_hour / s.parts     # refills an hour
        lines += ['', f'Time per vibration the refill interval allows: '
                  f'{fmt(s.minutes_per_vibration_allowed)} min. Parts spilled over the '
                  f'walls: {s.physics.spilled} (in {s.runs_spilling} runs; a run may '
                  f'spill {s.max_spilled}); runs emptied within that: {s.accepted}. Spilled '
                  f'per refill of {s.parts}: {fmt(per_refill, 3)}; per hour at the required '
                  f'{fmt(run.summary.requirements.parts_per_hour)} parts per hour: '
                  f'{fmt(per_refill * hourly, 3)}.']
        rate = s.parts_per_hour
        if rate.mean is not None:
            low, high = s.parts_per_hour_ci95
            lines += ['', f'The cell would pick {fmt(rate.mean, 4)} parts per hour (mean of '
                      f'{count(rate.n, "run")}'
                      + (f', 95 % interval {fmt(low, 4)} to {fmt(high, 4)}' if low is not None
                         else '')
                      + f'; required {fmt(run.summary.requirements.parts_per_hour)}'
                      f'): {fmt(s.cell.pick_s)} s per pick (`cell.pick_s`), '
                      f'{fmt(s.cell.image_s)} s per image after every pick and vibration '
                      '(`cell.image_s`), and the simulated time each feed and vibration took '
                      'until the parts rested.']
        return lines


# the file keys the feeding words give (report.read: those the file does not set)
FEEDING = ('hopper_lip_mm', 'hopper_rate', 'hopper_speed_mm_s', 'feeder_zone_mm', 'tray_mm')


def feeding(tray: dict, dose: int, unset: tuple[str, ...] = ()) -> str:
    """How the parts reached the tray, in words, from what the run ran with (resolved.json's
    `tray`, mm); `unset`: those of FEEDING the file left to their defaults. A run from before
    the hopper metered (no `hopper_rate`) had its parts dropped from the lip or the pile."""
    (cx, cy), (sx, sy) = tray['feeder_zone_mm']['center'], tray['feeder_zone_mm']['size']
    x, y, z = tray['tray_mm']
    lip = cx - sx / 2 if cx <= 0 else cx + sx / 2
    how = (f'The hopper let the parts out of its outlet {fmt(tray["hopper_lip_mm"])} mm over '
           f'the plate (`hopper_lip_mm`), at x {fmt(lip, 4)} mm across y {fmt(cy - sy / 2, 4)} '
           f'to {fmt(cy + sy / 2, 4)} mm (the outer edge of `feeder_zone_mm`), '
           f'{fmt(tray["hopper_rate"])} parts a second (`hopper_rate`) moving onto the tray at '
           f'{fmt(tray["hopper_speed_mm_s"])} mm/s (`hopper_speed_mm_s`), for the time a dose '
           'takes at that rate, a part waiting where the pile stood at the outlet, '
           if 'hopper_rate' in tray else
           f'The hopper fed the parts from {fmt(tray["hopper_lip_mm"])} mm over the plate '
           f'(`hopper_lip_mm`), or from just above the pile where it stood higher, onto the '
           f'feeder zone x {fmt(cx - sx / 2, 4)} to {fmt(cx + sx / 2, 4)} mm, '
           f'y {fmt(cy - sy / 2, 4)} to {fmt(cy + sy / 2, 4)} mm (`feeder_zone_mm`) ')
    return (how + f'of the {fmt(x)} x {fmt(y)} mm tray with {fmt(z)} mm walls (`tray_mm`), '
            + (f'at most {dose} parts a feed, the fill to max* going on over several '
               'vibrations (`max_feed`).' if dose else
               'a dose of the whole shortfall to max* (`max_feed` would limit it).')
            + (f' The file sets no {", ".join(f"`{k}`" for k in unset)}: the run took '
               + ('its default.' if len(unset) == 1 else 'their defaults.') if unset else ''))
