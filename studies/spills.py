"""Parts that leave the tray in PTH1 feeder runs, per solver setting: seeded feeder_emptying
runs of TO-220s at the reduced test case's optimal range [44, 54]; prints per run the parts
spilled (outside the tray, not through it), tunnelled, vibrations, picks and parts still
moving at a settle's end.

    tools/ws python -m studies.spills [--settings default,warm-0.85] [--runs 4]
        [--parts 200]
"""

import argparse
from dataclasses import replace

from pick_sim_world.config import PhysicsConfig

from studies.cases import parse_args, run_on_cores

SETTINGS = {'default': {}, 'warm-0.85': {'warm_starting_factor': 0.85},
            'warm-0.1': {'warm_starting_factor': 0.1},
            'former': {'solver_iterations': 30, 'warm_starting_factor': 0.1},
            'dt/2': {'time_step': PhysicsConfig().time_step / 2}}


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--settings', 'default', '--runs', '1', '--parts', '20']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--settings', default=','.join(SETTINGS))
    parser.add_argument('--runs', type=int, default=4)
    parser.add_argument('--parts', type=int, default=200)
    args = parse_args(parser, SMALL)
    for name in args.settings.split(','):
        rows, wall = run_on_cores('pth1.yaml', [{
            'id': 'feeder', 'type': 'feeder_emptying', 'iterations': args.runs,
            'parts': args.parts, 'optimal_range': [44, 54], 'max_vibrations': 500}],
            replace(PhysicsConfig(), **SETTINGS[name]))
        print(f'{name}: ' + '; '.join(f'{k} {[r[k] for r in rows]}' for k in (
            'spilled', 'tunnelled', 'vibrations', 'picks', 'unsettled'))
            + f'; wall {wall:.0f} s', flush=True)


if __name__ == '__main__':
    main()
