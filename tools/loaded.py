"""Run a command on a busy machine: start CPU-bound loops (one per CPU by default), run the
command `--rounds` times in a row, stop the loops, and say which rounds passed. The exit
status is the first failing round's (0 when all passed).

    python3 tools/loaded.py [--rounds 3] [--loops N] -- make test

`make test-loaded` runs the test command three times so (docs/reliability.md, "A busy
machine"). A test that passes
here only by luck of scheduling would fail on a shared CI machine or a busy workstation.
"""

import argparse
import multiprocessing
import os
import subprocess
import sys
import time


def burn() -> None:
    """A CPU-bound loop that never yields: the load a compiler or a simulation puts on a core."""
    x = 0
    while True:
        x = (x * 1103515245 + 12345) & 0xFFFFFFFF


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rounds', type=int, default=3, help='times to run the command')
    parser.add_argument('--loops', type=int, default=os.cpu_count() or 1,
                        help='CPU-bound loops beside it (default: one per CPU)')
    parser.add_argument('command', nargs=argparse.REMAINDER, help='-- then the command')
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ['--'] else args.command
    if not command:
        parser.error('give the command after --')
    if args.rounds < 1 or args.loops < 0:
        parser.error('--rounds must be at least 1 and --loops at least 0')
    loops = [multiprocessing.Process(target=burn, daemon=True) for _ in range(args.loops)]
    for loop in loops:
        loop.start()
    results = []
    try:
        for k in range(1, args.rounds + 1):
            print(f'loaded: round {k} of {args.rounds}, {args.loops} CPU-bound loops beside '
                  f'{" ".join(command)}', flush=True)
            start = time.monotonic()
            code = subprocess.call(command)
            results.append(code)
            print(f'loaded: round {k}: exit {code} after '
                  f'{(time.monotonic() - start) / 60:.1f} min', flush=True)
    finally:
        for loop in loops:
            loop.terminate()
        for loop in loops:
            loop.join()
    passed = sum(code == 0 for code in results)
    print(f'loaded: {passed} of {len(results)} rounds passed', flush=True)
    return next((code for code in results if code != 0), 0)


if __name__ == '__main__':
    sys.exit(main())
