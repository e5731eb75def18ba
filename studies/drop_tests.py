"""Resting poses against published drop tests: single parts dropped many times onto a floor,
the share of each aspect they come to rest on, measured by others beside this simulation's
and the quasi-static prediction (pick_common.parts.aspects).

    tools/ws python -m studies.drop_tests [--drops 400] [--height-mm 100] [--only NAME ...]
        [--calibrate] [--figure PNG] [--workers 1] [--output DIR]

Data sets (each with its source; see docs/drop-tests.md):
- murray_thick, murray_thin: a nylon cylinder, length = diameter = 19.1 mm, dropped on glass:
  both ends together 0.38 of throws on a 15.5 mm plate, 0.24 on a 2.4 mm one (D. B. Murray's
  group, dice physics pages, Okanagan University College, 2002; shares, no counts given);
- dice_3pct: a 16 mm die (size assumed) one axis 3 % short: each of its two large faces about
  0.177 (same group, 6th Experimental Chaos Conference, 2001; share);
- binom3, binom4: Baktash et al.'s 3D-printed polyhedra (SIGGRAPH 2025, data MIT-licensed in
  src/experiment_manager/config/parts/resting_rigid_bodies), with counts; printed size and
  material assumed (40 mm longest, PLA).
Each is dropped `--drops` times from `--height-mm` (the sources do not say from how high) with
a uniformly random orientation and left to rest, by the `drop_test` experiment a user runs (one
part a drop onto its plate; run in this process on --workers local workers, no graph).
--calibrate fits the restitution against the floor on murray_thick (a grid of 0.1 to
0.7) and checks the others at the fitted value: calibrated on one data set, checked on the
rest. Prints per data set and aspect: measured share (its 95 % interval where counts are
given), simulated share [95 % interval], quasi-static share; and the G-test p where counts are
given. --figure draws measured, simulated and quasi-static shares side by side.
"""

import argparse
from collections import Counter
from dataclasses import dataclass, field, replace
import os
import tempfile

from experiment_manager import experiment_file
import numpy as np
from pick_common.parts import aspects as aspects_of
from pick_common.parts.materials import Contact, PART_ON_SURFACE
from pick_common.stats import wilson_interval
import trimesh

from studies.cases import run_file

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src', 'experiment_manager',
                    'config', 'parts', 'resting_rigid_bodies')


@dataclass(frozen=True)
class DataSet:
    """A published drop test: the shape (a trimesh in metres, its frame as the outcomes'),
    the density (kg/m^3), the measured outcome -> aspects it counts, its shares or counts, and
    where it comes from."""

    shape: object
    density: float
    outcomes: dict[str, tuple[str, ...]]
    shares: dict[str, float] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    source: str = ''


def _cylinder() -> trimesh.Trimesh:
    return trimesh.creation.cylinder(radius=0.00955, height=0.0191, sections=64)


def _polyhedron(name: str) -> trimesh.Trimesh:
    mesh = trimesh.load(os.path.join(DATA, f'{name}.obj'))
    mesh.apply_scale(0.04 / mesh.extents.max())
    return mesh


def _outcomes(name: str, normals: list[tuple[float, float, float]]) -> dict:
    """Outcome i of Baktash et al.'s csv is the i-th normal of final_normal_probs.json: the
    aspect of the shape whose normal it is."""
    mesh = _polyhedron(name)
    found = aspects_of.stable_aspects(mesh, mesh.center_mass)
    return {f'outcome_{i}': (max(found, key=lambda a: np.dot(a.normal, n)).name,)
            for i, n in enumerate(normals)}


BINOM3_NORMALS = [(0.90995, 0.41469, -0.00373), (-0.34730, 0.93774, -0.00580),
                  (-0.34730, -0.93774, -0.00580), (0.90995, -0.41469, -0.00373)]
BINOM4_NORMALS = [(0.97767, 0.21013, -0.00007), (0.38195, 0.92417, 0.00437),
                  (-1.00000, -0.00006, -0.00126), (0.38221, -0.92408, -0.00071),
                  (0.97757, -0.21062, -0.00132)]


def datasets() -> dict[str, DataSet]:
    murray = 'D. B. Murray et al., dice physics pages, Okanagan University College (2002)'
    return {
        'murray_thick': DataSet(_cylinder(), 1140.0, {'ends': ('+z', '-z'), 'side': ('side_z',)},
                                shares={'ends': 0.38, 'side': 0.62},
                                source=f'{murray}: nylon on a 15.5 mm glass plate'),
        'murray_thin': DataSet(_cylinder(), 1140.0, {'ends': ('+z', '-z'), 'side': ('side_z',)},
                               shares={'ends': 0.24, 'side': 0.76},
                               source=f'{murray}: nylon on a 2.4 mm glass plate'),
        'dice_3pct': DataSet(trimesh.creation.box((0.016, 0.016, 0.016 * 0.97)), 1180.0,
                             {'short_axis_face': ('+z',), 'other_short_axis_face': ('-z',)},
                             shares={'short_axis_face': 0.177, 'other_short_axis_face': 0.177},
                             source='D. B. Murray and S. W. Teare et al., 6th Experimental '
                             'Chaos Conference (2001): a die 3 % short on one axis'),
        'binom3': DataSet(_polyhedron('binom3'), 1240.0, _outcomes('binom3', BINOM3_NORMALS),
                          counts={'outcome_0': 43, 'outcome_1': 138, 'outcome_2': 117,
                                  'outcome_3': 31},
                          source='Baktash et al., SIGGRAPH 2025, binom3.csv (329 drops)'),
        'binom4': DataSet(_polyhedron('binom4'), 1240.0, _outcomes('binom4', BINOM4_NORMALS),
                          counts={'outcome_0': 4, 'outcome_1': 119, 'outcome_2': 167,
                                  'outcome_3': 104, 'outcome_4': 10},
                          source='Baktash et al., SIGGRAPH 2025, binom4.csv (404 drops)'),
    }


def drop(mesh: trimesh.Trimesh, density: float, contact: Contact, height: float, drops: int,
         workers: int = 1, keep: str = '') -> tuple[Counter, tuple]:
    """`drops` parts of `mesh` dropped from `height` (m) with `contact` against the floor, as
    a `drop_test` experiment drops them (one part a drop, the experiment's plate; run in this
    process on `workers` local workers, running.local_backend): the count of each aspect they
    rest on (aspects.OTHER: on none), and the aspects. `keep`: a directory the run's files
    are kept in (its experiment file, part, iterations.csv with each drop's aspect, parts.csv
    with each part's pose at rest, summary.json), to look at; '' keeps nothing."""
    with tempfile.TemporaryDirectory() as scratch:
        tmp = keep or scratch
        os.makedirs(tmp, exist_ok=True)
        path = os.path.join(tmp, 'part.stl')
        mesh.export(path)
        opening = 1.5 * float(mesh.extents.max()) * 1000.0     # the grasp is not looked at
        floor = ', '.join(f'{key}: {float(value)!r}' for key, value in (
            ('lateral_friction', contact.lateral_friction), ('restitution', contact.restitution),
            ('rolling_friction_mm', contact.rolling_friction * 1000.0),
            ('spinning_friction_mm', contact.spinning_friction * 1000.0)))
        text = f"""id: drops
seed: 0
part:
  model: mesh
  mesh: {path}
  units: m
  mass_g: {float(density * mesh.volume * 1000.0)!r}
  place: {{axis: [0, 0, -1], seat_offset_mm: 0}}
  grasps: [{{name: across, up_axis: [1, 0, 0], closing_axis: [0, 1, 0],
             jaw_opening_mm: {opening!r}}}]
materials:
  part_on_surface: {{{floor}, source: studies/drop_tests.py}}
experiments:
  - {{id: drops, type: drop_test, iterations: {drops}, height_mm: {height * 1000.0!r}}}
"""
        file = experiment_file.parse(text, os.path.join(tmp, 'drops.yaml'))
        summary = run_file(file, os.path.join(tmp, 'run'), workers)
    found = summary.experiments['drops']
    counts = Counter({a.name: a.count for a in found.aspects if a.count})
    if found.other:
        counts[aspects_of.OTHER] = found.other
    return counts, file.aspects


def shares_of(counts: Counter, outcomes: dict[str, tuple[str, ...]]) -> dict[str, int]:
    """The counts of the data set's outcomes from counts of aspects."""
    return {o: sum(counts.get(a, 0) for a in names) for o, names in outcomes.items()}


def compare(name: str, data: DataSet, contact: Contact, height: float, drops: int,
            workers: int = 1, keep: str = '') -> dict:
    counts, found = drop(data.shape, data.density, contact, height, drops, workers, keep)
    simulated = shares_of(counts, data.outcomes)
    total = sum(counts.values())
    quasi = {o: sum(a.quasi_static for a in found if a.name in names)
             for o, names in data.outcomes.items()}
    measured_total = sum(data.counts.values())
    rows = []
    for o in data.outcomes:
        measured = (data.counts[o] / measured_total if data.counts else data.shares[o])
        rows.append({'outcome': o, 'measured': measured,
                     'measured_ci': wilson_interval(data.counts[o], measured_total)
                     if data.counts else None,
                     'simulated': simulated[o] / total,
                     'simulated_ci': wilson_interval(simulated[o], total),
                     'quasi_static': quasi[o]})
    p = aspects_of.agreement(simulated, data.counts) if data.counts else None
    return {'name': name, 'rows': rows, 'other': counts.get(aspects_of.OTHER, 0),
            'drops': total, 'p': p, 'source': data.source}


def describe(result: dict) -> str:
    lines = [f'{result["name"]} ({result["source"]}): {result["drops"]} drops, '
             f'{result["other"]} on no aspect'
             + (f', G-test p {result["p"]:.3g}' if result['p'] is not None else '')]
    for r in result['rows']:
        ci = r['measured_ci']
        measured = f'{r["measured"]:.3f}' + (f' [{ci[0]:.3f}, {ci[1]:.3f}]' if ci else '')
        lo, hi = r['simulated_ci']
        lines.append(f'  {r["outcome"]:<24} measured {measured:<22} simulated '
                     f'{r["simulated"]:.3f} [{lo:.3f}, {hi:.3f}]  quasi-static '
                     f'{r["quasi_static"]:.3f}')
    return '\n'.join(lines)


def calibrate(data: DataSet, height: float, drops: int, workers: int = 1
              ) -> tuple[float, list]:
    """The restitution against the floor (0.1 to 0.7) whose simulated share of the data set's
    first outcome lies nearest the measured one; and the grid's (e, share) pairs. Nearest, not
    likeliest: the thick plate's data give a share of throws whose number is not published,
    and the likelihood a sensitivity's calibration ranks points by (analysis/calibration.py)
    needs counts."""
    outcome = next(iter(data.outcomes))
    grid = []
    for e in (0.1, 0.3, 0.5, 0.7):
        counts, _ = drop(data.shape, data.density, replace(PART_ON_SURFACE, restitution=e),
                         height, drops, workers)
        grid.append((e, shares_of(counts, data.outcomes)[outcome] / sum(counts.values())))
    target = data.shares[outcome]
    return min(grid, key=lambda g: abs(g[1] - target))[0], grid


def figure(results: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(results), figsize=(3.2 * len(results), 3.2), squeeze=False)
    for ax, result in zip(axes[0], results, strict=True):
        rows = result['rows']
        x = np.arange(len(rows))
        for k, (key, label) in enumerate((('measured', 'measured'), ('simulated', 'simulated'),
                                          ('quasi_static', 'quasi-static'))):
            ax.bar(x + (k - 1) * 0.27, [r[key] for r in rows], 0.27, label=label)
        ax.errorbar(x, [r['simulated'] for r in rows],
                    yerr=np.array([[r['simulated'] - r['simulated_ci'][0],
                                    r['simulated_ci'][1] - r['simulated']] for r in rows]).T,
                    fmt='none', ecolor='black', capsize=2)
        ax.set_xticks(x, [r['outcome'].replace('_', ' ') for r in rows], rotation=30,
                      ha='right', fontsize=7)
        ax.set_title(result['name'], fontsize=9)
        ax.set_ylim(0, 1)
    axes[0][0].set_ylabel('share of drops')
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--drops', type=int, default=400)
    parser.add_argument('--height-mm', type=float, default=100.0)
    parser.add_argument('--only', nargs='*', default=None)
    parser.add_argument('--calibrate', action='store_true')
    parser.add_argument('--figure', default='')
    parser.add_argument('--workers', type=int, default=1)
    parser.add_argument('--output', default='',
                        help="keep each data set's run in OUTPUT/<name> (its parts' poses at "
                        'rest in parts.csv), to look at')
    args = parser.parse_args(argv)
    height = args.height_mm / 1000.0
    sets = datasets()
    contact = PART_ON_SURFACE
    if args.calibrate:
        e, grid = calibrate(sets['murray_thick'], height, args.drops, args.workers)
        print('calibrated on murray_thick (ends share against restitution): '
              + ', '.join(f'e {g:.1f}: {s:.3f}' for g, s in grid) + f'; fitted e = {e:.1f}')
        contact = replace(contact, restitution=e)
    print(f'floor contact: {contact}; drop height {args.height_mm:g} mm')
    results = []
    for name in args.only or sets:
        results.append(compare(name, sets[name], contact, height, args.drops, args.workers,
                               os.path.join(args.output, name) if args.output else ''))
        print(describe(results[-1]), flush=True)
    if args.figure:
        figure(results, args.figure)
        print(f'figure: {args.figure}')


if __name__ == '__main__':
    main()
