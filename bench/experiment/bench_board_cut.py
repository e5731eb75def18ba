"""How long a board's models take to read and cut: each distinct through-hole part of a KiCad
board read from its STEP file and cut into its collision pieces (CoACD), on a fresh pieces'
cache, one after the other on one core (the baseline, each part's own time against the
target of 20 s a model on one core, with its pieces' volume against the part's), then all of
them side by side on N processes (`board.cutting.cut_side_by_side`, as `run` does before the
parts are read in turn), again on a fresh cache: the wall time and its ratio to the baseline.

    tools/ws python -m bench.experiment.bench_board_cut [BOARD.yaml] [--workers 2]

BOARD.yaml: a board experiment file (default: config/boards/ecc83.yaml).
"""

import argparse
import os
import tempfile
import time

from ament_index_python.packages import get_package_share_directory
from experiment_manager.experiment_file.board import cut_side_by_side, load_board, write_parts
from experiment_manager.experiment_file.board.cutting import cut
from experiment_manager.experiment_file.loading import part_of
from experiment_manager.experiment_file.part import geometry
from pick_common.parts.primitives import Hull
import trimesh

TARGET_S = 20.0     # issue 63: each model read and cut in at most 20 s on one core


def _fresh_cache(root: str, name: str) -> None:
    os.environ['PICK_SIM_CACHE'] = os.path.join(root, name)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('board', nargs='?', default=os.path.join(
        get_package_share_directory('experiment_manager'), 'config', 'boards', 'ecc83.yaml'))
    parser.add_argument('--workers', type=int, default=2)
    args = parser.parse_args()
    board = load_board(os.path.abspath(args.board))
    with tempfile.TemporaryDirectory() as root:
        files = write_parts(board, os.path.join(root, 'parts'))
        print(f'{board.path}: {len(files)} part(s) to read')
        _fresh_cache(root, 'one')
        start = time.perf_counter()
        for name, path in files.items():
            began = time.perf_counter()
            cut(path)
            took = time.perf_counter() - began
            try:
                part = geometry(part_of(path))      # from the cache now
                pieces = sum(trimesh.Trimesh(h.vertices, h.faces).volume
                             for h in part.primitives if isinstance(h, Hull))
                said = f'{len(part.primitives)} pieces'
                over = f'{100 * (pieces / part.volume - 1):+.1f} %'
            except Exception as exc:    # a part that does not read: its reason
                said, over = f'does not read: {str(exc)[:60]}', ''
            print(f'  {name[:50]:50s} {took:7.1f} s ({took / TARGET_S:4.1f} x target) '
                  f'{over:>9s} on its volume  {said}', flush=True)
        one = time.perf_counter() - start
        _fresh_cache(root, 'many')
        start = time.perf_counter()
        cut_side_by_side(list(files.values()), args.workers)
        many = time.perf_counter() - start
    print(f'one core, in turn: {one:.1f} s; {args.workers} processes side by side: {many:.1f} s '
          f'(ratio {one / many:.2f})')


if __name__ == '__main__':
    main()
