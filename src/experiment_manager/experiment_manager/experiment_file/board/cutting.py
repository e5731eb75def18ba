"""A board's parts cut side by side: each part's collision pieces (CoACD's cut,
pick_common.parts.pieces, the slow step of reading a model: 57 to 102 s of one core for a DIP
socket, a D-sub or a terminal block, docs/boards.md) made on a pool of processes before the
parts are read in turn, which then find them in the pieces' cache. The cut is the same
whichever process makes it (a fixed seed, one thread, its result keyed by the mesh), so the
answer does not depend on the pool."""

from concurrent.futures import ProcessPoolExecutor
import multiprocessing

from ..loading import part_of
from ..part import geometry


def cut_side_by_side(paths: list[str], workers: int) -> None:
    """Build the part of each experiment file in `paths` on up to `workers` processes (none
    for fewer than two of either). A part that does not read is left to its reading in turn
    to say why."""
    if workers < 2 or len(paths) < 2:
        return
    # spawned, not forked: the caller may hold rclpy's threads
    context = multiprocessing.get_context('spawn')
    with ProcessPoolExecutor(min(workers, len(paths)), mp_context=context) as pool:
        list(pool.map(cut, paths))


def cut(path: str) -> None:
    """Build the part of the experiment file at `path`, its pieces into the cache; nothing
    when it does not read (its reading in turn raises that, named)."""
    try:
        geometry(part_of(path))
    except Exception:   # any error: said by the part's reading in turn
        pass
