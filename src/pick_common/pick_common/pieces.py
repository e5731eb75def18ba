"""Convex pieces of a concave part mesh, by CoACD, cached on disk.

A moving body collides as a compound of convex pieces; one hull over a concave part (a TO-220
with its tab hole and three leads: 852 mm^3 of hull over 487 mm^3 of part) fills its gaps and
makes it collide where it has no material. CoACD (Wei et al., SIGGRAPH 2022; the `coacd`
wheel) cuts a closed mesh into pieces whose concavity is at most `THRESHOLD`.

Its settings, and where they come from:
- THRESHOLD 0.05: CoACD's own default concavity threshold (its README's `-t`), a fraction of
  the part's size.
- MAX_PIECES 32: the compound's limit that a mesh's connected bodies already had
  (`parts.MAX_MESH_HULLS`).
- MAX_PIECE_VERTICES 64: CoACD's decimation cap (`max_ch_vertex`, default 256) lowered, because
  a 1,090-vertex hull made table drops 4 to 7 times slower (issue 42's measurement); a small
  part's piece rarely needs more than a few dozen (TO-220: at most 25).
- SEED 0: CoACD's search is random; a fixed seed makes it give the same pieces each time
  (checked: three runs of the TO-220, the same nine pieces; their order and vertex order
  vary, so `convex_pieces` sorts both).

Decomposing takes about a second for a small part (TO-220: 1.1-1.6 s), and every node that
builds the part would pay it, so the pieces are kept in a cache directory keyed by a hash of
the mesh and the settings: `$PICK_SIM_CACHE`, else `$XDG_CACHE_HOME/pick_sim`, else
`~/.cache/pick_sim`. A lock on the entry makes nodes that start together compute it once and
read the same pieces.
"""

import fcntl
import hashlib
import os
import tempfile

import numpy as np
import trimesh

THRESHOLD = 0.05
MAX_PIECES = 32
MAX_PIECE_VERTICES = 64
SEED = 0
# A closed body whose hull exceeds its volume by less than this is kept as its hull: it is
# convex but for its tessellation (a cylinder's facets).
CONVEX_SLACK = 0.02


def cache_dir() -> str:
    """Where decompositions are kept (created on first use)."""
    root = (os.environ.get('PICK_SIM_CACHE')
            or os.path.join(os.environ.get('XDG_CACHE_HOME')
                            or os.path.join(os.path.expanduser('~'), '.cache'), 'pick_sim'))
    return os.path.join(root, 'pieces')


def is_convex(body: trimesh.Trimesh) -> bool:
    """A closed body whose convex hull is within CONVEX_SLACK of its own volume."""
    return body.convex_hull.volume <= (1.0 + CONVEX_SLACK) * body.volume


def _key(body: trimesh.Trimesh) -> str:
    import coacd
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(body.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(body.faces, dtype=np.int64).tobytes())
    h.update(repr((THRESHOLD, MAX_PIECES, MAX_PIECE_VERTICES, SEED,
                   getattr(coacd, '__version__', ''))).encode())
    return h.hexdigest()


def _decompose(body: trimesh.Trimesh) -> list[np.ndarray]:
    import coacd
    coacd.set_log_level('error')
    pieces = coacd.run_coacd(coacd.Mesh(np.asarray(body.vertices, dtype=np.float64),
                                        np.asarray(body.faces, dtype=np.int64)),
                             threshold=THRESHOLD, max_convex_hull=MAX_PIECES,
                             max_ch_vertex=MAX_PIECE_VERTICES, decimate=True, seed=SEED,
                             preprocess_mode='off')
    # the same pieces in one order, each with its points in one order
    points = [np.asarray(v, dtype=np.float64) for v, _ in pieces]
    points = [p[np.lexsort(p.T[::-1])] for p in points if len(p) >= 4]
    return sorted(points, key=lambda p: tuple(np.round(p.mean(axis=0), 9)))


def convex_pieces(body: trimesh.Trimesh) -> list[np.ndarray]:
    """The vertex sets (each (K, 3) float64, in the body's frame) of CoACD's convex pieces of a
    closed body. CoACD cuts along planes square to the frame's axes, so the body is cut in its
    own principal frame (its mass centre and axes of inertia) and the pieces are turned back:
    where a file puts its origin or how it turns its axes does not change the cut (KiCad's
    TO-220 turned in its file came out in 27 pieces, in its own frame in 9)."""
    to_principal = body.principal_inertia_transform
    canonical = body.copy()
    canonical.apply_transform(to_principal)
    back = np.linalg.inv(to_principal)
    return [p @ back[:3, :3].T + back[:3, 3] for p in _cached_pieces(canonical)]


def _cached_pieces(body: trimesh.Trimesh) -> list[np.ndarray]:
    """CoACD's pieces of `body` as it lies, from the cache when it holds them."""
    directory = cache_dir()
    try:
        os.makedirs(directory, exist_ok=True)
        lock = open(os.path.join(directory, 'lock'), 'w')
    except OSError:                     # no cache where none can be written: compute each time
        return _decompose(body)
    path = os.path.join(directory, _key(body) + '.npz')
    with lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            with np.load(path) as stored:
                return [stored[f'p{i}'] for i in range(len(stored.files))]
        except (OSError, ValueError, KeyError):     # not there yet, or unreadable: compute
            pass
        points = _decompose(body)
        fd, tmp = tempfile.mkstemp(dir=directory, suffix='.npz')
        with os.fdopen(fd, 'wb') as out:
            np.savez(out, **{f'p{i}': p for i, p in enumerate(points)})
        os.replace(tmp, path)
        return points
