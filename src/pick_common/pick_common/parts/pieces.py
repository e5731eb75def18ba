"""The convex pieces a mesh part collides as (`convex_cover`): a hull per convex or open body,
and CoACD's pieces of a concave closed one, cached on disk.

A moving body collides as a compound of convex pieces; one hull over a concave part (a TO-220
with its tab hole and three leads: 852 mm^3 of hull over 487 mm^3 of part) fills its gaps and
makes it collide where it has no material. CoACD (Wei et al., SIGGRAPH 2022; the `coacd`
wheel) cuts a closed mesh into pieces whose concavity is at most `THRESHOLD`.

Its settings, and where they come from:
- THRESHOLD 0.05: CoACD's own default concavity threshold (its README's `-t`), a fraction of
  the part's size.
- MAX_PIECES 32: the compound's limit that a mesh's connected bodies already had
  (`MAX_MESH_HULLS`).
- MAX_PIECE_VERTICES 64: CoACD's decimation cap (`max_ch_vertex`, default 256) lowered, because
  a 1,090-vertex hull made table drops 4 to 7 times slower (docs/benchmarks.md); a small
  part's piece rarely needs more than a few dozen (TO-220: at most 25).
- SEED 0 and one thread: CoACD's search is random; a fixed seed and one OpenMP thread make
  it give the same pieces each time (checked: the TO-220 three times, the same nine pieces;
  KiCad's DIP-40 socket twice on one thread, the same 13, where on two threads it gave 13, then
  9). The pieces' order and vertex order vary, so `convex_pieces` sorts both.

Decomposing takes about a second for a small part (TO-220: 1.1-1.6 s), and every node that
builds the part would pay it, so the pieces are kept in a cache directory keyed by a hash of
the mesh and the settings: `$PICK_SIM_CACHE`, else `$XDG_CACHE_HOME/pick_sim`, else
`~/.cache/pick_sim`. A lock on the entry (a file beside it) makes nodes that start together
compute it once and read the same pieces, and lets different parts be cut side by side.
"""

import fcntl
import hashlib
import os
import sys
import tempfile

import numpy as np
import trimesh

from ..errors import MeshError

# The most convex pieces a part collides as, in all.
MAX_MESH_HULLS = 32
THRESHOLD = 0.05
MAX_PIECES = 32
MAX_PIECE_VERTICES = 64
SEED = 0
# A closed body whose hull exceeds its volume by less than this is kept as its hull: it is
# convex but for its tessellation (a cylinder's facets).
CONVEX_SLACK = 0.02
# Pieces whose volume together exceeds the part's by more than this make the part's account
# say why (`why_larger`): the allowance the board's issue sets for a model read at board
# scale, not a measured figure.
VOLUME_SLACK = 0.15


def cache_dir() -> str:
    """Where decompositions are kept (created on first use)."""
    root = (os.environ.get('PICK_SIM_CACHE')
            or os.path.join(os.environ.get('XDG_CACHE_HOME')
                            or os.path.join(os.path.expanduser('~'), '.cache'), 'pick_sim'))
    return os.path.join(root, 'pieces')


def is_convex(body: trimesh.Trimesh) -> bool:
    """A closed body whose convex hull is within CONVEX_SLACK of its own volume."""
    return body.convex_hull.volume <= (1.0 + CONVEX_SLACK) * body.volume


def _coacd():
    """The coacd module, its OpenMP runtime on one thread. On more, CoACD's search is not
    repeatable: KiCad's DIP-40 socket cut twice in one process on 2 threads gave 13 pieces,
    then 9; on one thread, the same 13 each time (docs/boards.md). Its wheel carries its own
    libgomp, which reads OMP_NUM_THREADS when it loads: set for that import only."""
    if 'coacd' not in sys.modules:
        saved = os.environ.get('OMP_NUM_THREADS')
        os.environ['OMP_NUM_THREADS'] = '1'
        try:
            import coacd  # loaded here, with its one thread
        finally:
            if saved is None:
                del os.environ['OMP_NUM_THREADS']
            else:
                os.environ['OMP_NUM_THREADS'] = saved
    coacd = sys.modules['coacd']
    coacd.set_log_level('error')
    return coacd


def _key(body: trimesh.Trimesh, most: int) -> str:
    coacd = _coacd()
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(body.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(body.faces, dtype=np.int64).tobytes())
    # 'one thread': pieces cut on more (before it was fixed) are not read back
    h.update(repr((THRESHOLD, most, MAX_PIECE_VERTICES, SEED,
                   getattr(coacd, '__version__', ''), 'one thread')).encode())
    return h.hexdigest()


def _decompose(body: trimesh.Trimesh, most: int) -> list[np.ndarray]:
    coacd = _coacd()
    pieces = coacd.run_coacd(coacd.Mesh(np.asarray(body.vertices, dtype=np.float64),
                                        np.asarray(body.faces, dtype=np.int64)),
                             threshold=THRESHOLD, max_convex_hull=most,
                             max_ch_vertex=MAX_PIECE_VERTICES, decimate=True, seed=SEED,
                             preprocess_mode='off')
    # the same pieces in one order, each with its points in one order
    points = [np.asarray(v, dtype=np.float64) for v, _ in pieces]
    points = [p[np.lexsort(p.T[::-1])] for p in points if len(p) >= 4]
    return sorted(points, key=lambda p: tuple(np.round(p.mean(axis=0), 9)))


def convex_pieces(body: trimesh.Trimesh, most: int = MAX_PIECES) -> list[np.ndarray]:
    """The vertex sets (each (K, 3) float64, in the body's frame) of CoACD's convex pieces of a
    closed body, at most `most` of them (CoACD merges its pieces down to that many). CoACD
    cuts along planes square to the frame's axes, so the body is cut in its
    own principal frame (its mass centre and axes of inertia) and the pieces are turned back:
    where a file puts its origin or how it turns its axes does not change the cut (KiCad's
    TO-220 turned in its file came out in 27 pieces, in its own frame in 9)."""
    to_principal = body.principal_inertia_transform
    canonical = body.copy()
    canonical.apply_transform(to_principal)
    back = np.linalg.inv(to_principal)
    return [p @ back[:3, :3].T + back[:3, 3] for p in _cached_pieces(canonical, most)]


def _cached_pieces(body: trimesh.Trimesh, most: int) -> list[np.ndarray]:
    """CoACD's pieces of `body` as it lies, from the cache when it holds them."""
    directory = cache_dir()
    key = _key(body, most)
    try:
        os.makedirs(directory, exist_ok=True)
        # a lock per entry: processes cutting different parts (a board's, side by side) do
        # not wait on each other; two asking for the same part cut it once
        lock = open(os.path.join(directory, key + '.lock'), 'w')
    except OSError:                     # no cache where none can be written: compute each time
        return _decompose(body, most)
    path = os.path.join(directory, key + '.npz')
    with lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            with np.load(path) as stored:
                return [stored[f'p{i}'] for i in range(len(stored.files))]
        except (OSError, ValueError, KeyError):     # not there yet, or unreadable: compute
            pass
        points = _decompose(body, most)
        fd, tmp = tempfile.mkstemp(dir=directory, suffix='.npz')
        with os.fdopen(fd, 'wb') as out:
            np.savez(out, **{f'p{i}': p for i, p in enumerate(points)})
        os.replace(tmp, path)
        return points


def _hull(points: np.ndarray) -> trimesh.Trimesh | None:
    try:
        hull = trimesh.convex.convex_hull(points)
    except Exception:  # qhull fails on flat or collinear input
        return None
    return hull if _has_volume(hull) else None


def _has_volume(body: trimesh.Trimesh) -> bool:
    """The body encloses space: a flat closed sheet (KiCad's models have some) or a flat hull
    does not. Read without numpy's warning: trimesh divides by the volume for the mass centre,
    which is no fault of the part's."""
    with np.errstate(divide='ignore', invalid='ignore'):
        return body.volume > 0


def convex_cover(mesh: trimesh.Trimesh, path: str) -> tuple[list[trimesh.Trimesh], str]:
    """The convex pieces a mesh collides as, and how they were made, in words.

    Each connected body: closed and convex (`is_convex`), its hull; closed and concave,
    CoACD's pieces (`convex_pieces`); open, its hull (an open body has no inside to cut,
    so its concavities stay filled: said in the words). Where the pieces number more than
    MAX_MESH_HULLS in all, the concave bodies are cut again with the hulls left to them
    shared out (CoACD merges its pieces down to each one's share: a D-sub's shell of 32 pieces
    beside its one convex body); only where that leaves a concave body no piece, or the mesh
    has more than MAX_MESH_HULLS bodies, is the part one hull of the whole mesh, said too.
    """
    bodies = mesh.split(only_watertight=False)
    if len(bodies) > MAX_MESH_HULLS:
        return _whole(mesh, path, f'it has {len(bodies)} separate bodies, more than '
                      f'{MAX_MESH_HULLS}')
    closed = [b.is_watertight and _has_volume(b) for b in bodies]
    concave = [c and not is_convex(b) for b, c in zip(bodies, closed, strict=True)]
    hulls = [[] if c else [h for h in [_hull(b.vertices)] if h is not None]
             for b, c in zip(bodies, concave, strict=True)]
    failed = _cut(bodies, concave, hulls, MAX_PIECES)
    shared = ''
    simple = sum(len(h) for h, c in zip(hulls, concave, strict=True) if not c)
    if sum(len(h) for h in hulls) > MAX_MESH_HULLS and any(concave):
        share = (MAX_MESH_HULLS - simple) // sum(concave)
        if share < 1:
            return _whole(mesh, path, f'its {simple} convex or open bodies leave '
                          f'{MAX_MESH_HULLS - simple} pieces for {sum(concave)} concave ones')
        failed = _cut(bodies, concave, hulls, share)
        shared = f' (at most {share} each, to keep the part within {MAX_MESH_HULLS} pieces)'
    hulls = [h for body in hulls for h in body]       # in the bodies' order, as they were
    if not hulls:
        return _whole(mesh, path, 'no body of it has volume')
    if len(hulls) > MAX_MESH_HULLS:                   # CoACD did not merge down to its share
        return _whole(mesh, path, f'its pieces number {len(hulls)}, more than {MAX_MESH_HULLS}')
    counts = {'convex': sum(closed) - sum(concave), 'open': len(bodies) - sum(closed)}
    words = []
    if any(concave):
        words.append(f'{sum(concave)} concave closed body(ies) cut into convex pieces by '
                     f'CoACD (concavity threshold {THRESHOLD:g}){shared}')
    if counts['convex']:
        words.append(f'{counts["convex"]} convex closed body(ies) as its hull')
    if counts['open']:
        words.append(f'{counts["open"]} open body(ies) as its hull (not closed, so not cut: '
                     'its hollows and gaps collide as filled; close the mesh to have it cut)')
    return hulls, '; '.join(words) + failed


def why_larger(pieces_volume: float, part_volume: float) -> str:
    """'' when the pieces' volume is within VOLUME_SLACK of the part's; else why the part
    collides larger than it is, in words."""
    if pieces_volume <= (1.0 + VOLUME_SLACK) * part_volume:
        return ''
    return (f'more than {100 * VOLUME_SLACK:g} % over the part: CoACD stops cutting a piece '
            f"whose concavity is under its threshold ({THRESHOLD:g} of the part's size), so "
            "hollows shallower than that (a socket's contact holes, a housing's pockets), and "
            'every hollow of an open body, collide as filled; where the part lies or is '
            'gripped by them, it does so as a solid block')


def _cut(bodies: list[trimesh.Trimesh], concave: list[bool], hulls: list[list], most: int
         ) -> str:
    """Put into `hulls` each concave body's pieces (at most `most`), or its hull where CoACD
    fails on it; what failed, in words."""
    failed = ''
    for i, body in enumerate(bodies):
        if not concave[i]:
            continue
        try:
            pieces = [h for h in (_hull(p) for p in convex_pieces(body, most)) if h is not None]
        except Exception as exc:    # CoACD's C++ raises what it raises: keep the hull
            pieces, failed = [], f'; CoACD could not cut a body ({exc}): it is its hull'
        hulls[i] = pieces or [h for h in [_hull(body.vertices)] if h is not None]
    return failed


def _whole(mesh: trimesh.Trimesh, path: str, why: str) -> tuple[list[trimesh.Trimesh], str]:
    whole = _hull(mesh.vertices)
    if whole is None:
        raise MeshError('part.mesh_path', path, 'has zero volume (flat or a line)')
    return [whole], f'one convex hull of the whole mesh: {why}'
