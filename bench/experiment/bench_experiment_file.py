"""What reading an experiment file costs a user: the import of the reader in a fresh
interpreter, and the parse of the built-in file and the three test-case files (each builds its
part's geometry), first and then the median of repeats; against the YAML parse alone of the
same files in the same run.

    tools/ws python -m bench.experiment.bench_experiment_file [--repeats 20]
        [--module experiment_manager.experiment_file]

--module names the module whose `parse(text, path)` is measured: another version's reader
(for example commit 10416e4's `experiment_manager.config`, on a checkout of it) runs through
the same script.
"""

import argparse
import importlib
import os
import statistics
import subprocess
import sys
import time

import yaml

CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'src',
                      'experiment_manager', 'config')
FILES = [os.path.join(CONFIG, 'default_experiment.yaml')] + [
    os.path.join(CONFIG, 'test_case', f'pth{i}.yaml') for i in range(3)]


def import_time(module: str) -> float:
    """s to import `module` in a fresh interpreter."""
    code = (f'import time; t = time.perf_counter(); import {module}; '
            'print(time.perf_counter() - t)')
    out = subprocess.run([sys.executable, '-c', code], check=True, capture_output=True,
                         text=True)
    return float(out.stdout.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeats', type=int, default=20)
    parser.add_argument('--module', default='experiment_manager.experiment_file')
    args = parser.parse_args()
    texts = [(open(f, encoding='utf-8').read(), f) for f in FILES]
    imports = [import_time(args.module) for _ in range(3)]
    parse = importlib.import_module(args.module).parse
    start = time.perf_counter()
    for text, path in texts:
        parse(text, path)
    first = time.perf_counter() - start
    runs, yaml_runs = [], []
    for _ in range(args.repeats):
        start = time.perf_counter()
        for text, path in texts:
            parse(text, path)
        runs.append(time.perf_counter() - start)
        start = time.perf_counter()
        for text, _ in texts:
            yaml.safe_load(text)
        yaml_runs.append(time.perf_counter() - start)
    parsed, loaded = statistics.median(runs), statistics.median(yaml_runs)
    print(f'{args.module}: import {min(imports) * 1000:.0f} to {max(imports) * 1000:.0f} ms '
          f'(3 fresh interpreters)')
    print(f'the {len(texts)} files: first parse {first * 1000:.1f} ms, then median '
          f'{parsed * 1000:.1f} ms of {args.repeats}; YAML alone {loaded * 1000:.1f} ms '
          f'(ratio {parsed / loaded:.1f})')


if __name__ == '__main__':
    main()
