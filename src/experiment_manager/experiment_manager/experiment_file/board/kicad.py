"""A KiCad board file (`.kicad_pcb`) read for what a robot inserts: its footprints, each with
its reference, whether it is through-hole, and its 3D model with the model's offset, scale and
rotation; the models resolved to the STEP file KiCad's library ships beside each `.wrl`.

The format is KiCad's s-expression board file: KiCad 6 to 9 name a footprint `footprint`,
KiCad 5 and earlier `module` (KiCad's "File Formats" reference, Board File Format). What is
read of each:
- its library name, `at` (x y [angle]; mm, y down) and `layer` (F.Cu top, B.Cu bottom);
- its type: KiCad 6+ `(attr through_hole | smd [board_only] ...)`; no type means "other"
  (neither), `board_only` a footprint with no part (KiCad 5's `virtual`). KiCad 5 writes
  `(attr smd)` or `(attr virtual)` and nothing for a through-hole footprint, read as one
  when it has a plated hole (`(pad ... thru_hole ...)`), else as "other";
- its reference: `(fp_text reference "R1" ...)` (KiCad 5 to 7) or `(property "Reference"
  "R1" ...)` (KiCad 8+);
- its models: `(model PATH [hide] [(hide yes)] (offset (xyz mm)) (scale (xyz)) (rotate (xyz
  deg)))`; KiCad 5.0 and earlier give the offset as `(at (xyz inches))`. A hidden model is
  not the part. KiCad draws a model at T(offset) Rz(-rz) Ry(-ry) Rx(-rx) S(scale) of its file
  (3d-viewer's OpenGL renderer), in the footprint's frame: the board's top surface at z = 0
  and the leads into -z.
- Paths: `${VAR}` and `$(VAR)` from KiCad's variables: `${KIPRJMOD}` is the board's folder,
  the `KICAD<n>_3DMODEL_DIR` and `KISYS3DMOD` ones the 3D library's folder (`models`, else
  the environment's), any other from the environment. A relative path is looked for in the
  board's folder, then in the 3D library's (as KiCad's resolver does).

Every error names the board file, its line and what is wrong (`InvalidArgument`).
"""

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
import os
import re

import numpy as np
from pick_common.errors import InvalidArgument

INCH = 25.4                                     # mm, KiCad 5.0's model `at`
MAX_BOARD_BYTES = 64 * 1024 * 1024              # a 200 x 200 mm 6-layer board is ~10 MB
STEP_SUFFIXES = ('.step', '.stp', '.STEP', '.STP')
# The variables that name KiCad's 3D library: KiCad 5's, and KiCad 6 to 9's KICAD<n>_3DMODEL_DIR.
LIBRARY_VARIABLE = re.compile(r'KISYS3DMOD|KICAD\d+_3DMODEL_DIR')
_TOKEN = re.compile(r'"((?:[^"\\]|\\.)*)"|([()])|([^\s()"]+)|(\s+)', re.S)


@dataclass
class Node:
    """One list of the file: its items (str or Node) and the line it opens on."""
    items: list
    line: int

    @property
    def head(self) -> str:
        return self.items[0] if self.items and isinstance(self.items[0], str) else ''

    def children(self, name: str) -> Iterator['Node']:
        return (n for n in self.items if isinstance(n, Node) and n.head == name)

    def child(self, name: str) -> 'Node | None':
        return next(self.children(name), None)

    def atoms(self) -> list[str]:
        return [a for a in self.items[1:] if isinstance(a, str)]


def parse(text: str, path: str) -> Node:
    """The file's top list. Raises InvalidArgument naming `path` and the line for text that is
    not one balanced s-expression (a truncated file: the list left open and where)."""
    stack: list[Node] = []
    top = None
    line = 1
    for m in _TOKEN.finditer(text):
        quoted, paren, atom, space = m.groups()
        if space is not None:
            line += space.count('\n')
            continue
        if paren == '(':
            node = Node([], line)
            if stack:
                stack[-1].items.append(node)
            elif top is not None:
                raise InvalidArgument('board.pcb', path, f'line {line}: a second top-level list '
                                      f'after the board closed on line {top.line}')
            else:
                top = node
            stack.append(node)
        elif paren == ')':
            if not stack:
                raise InvalidArgument('board.pcb', path, f"line {line}: ')' closes no list")
            stack.pop()
        elif stack:
            value = atom if atom is not None else re.sub(r'\\(.)', r'\1', quoted)
            stack[-1].items.append(value)
            line += (quoted or '').count('\n')
        else:
            raise InvalidArgument('board.pcb', path, f'line {line}: {m.group(0)[:40]!r} '
                                  "outside the board's list")
    if stack:
        raise InvalidArgument('board.pcb', path, f'line {stack[-1].line}: the '
                              f'({stack[-1].head} ...) opened there is not closed by the end '
                              f'of the file (line {line}): is the file truncated?')
    if top is None or top.head != 'kicad_pcb':
        raise InvalidArgument('board.pcb', path, 'is not a KiCad board: it does not begin with '
                              '(kicad_pcb')
    return top


@dataclass(frozen=True)
class Model:
    """A footprint's 3D model as the board gives it: the path as written, the offset (mm),
    scale and rotation (degrees) KiCad applies to it."""
    path: str
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    rotate: tuple[float, float, float] = (0.0, 0.0, 0.0)
    line: int = 0

    def transform(self) -> np.ndarray:
        """The 4x4 matrix from the model file's frame (mm) to the footprint's, as KiCad draws
        it: T(offset) Rz(-rz) Ry(-ry) Rx(-rx) S(scale)."""
        rx, ry, rz = (np.radians(-a) for a in self.rotate)
        cx, sx, cy, sy, cz, sz = np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry), np.cos(rz), \
            np.sin(rz)
        turn_x = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
        turn_y = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
        turn_z = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
        out = np.eye(4)
        out[:3, :3] = turn_z @ turn_y @ turn_x @ np.diag(self.scale)
        out[:3, 3] = self.offset
        return out


@dataclass(frozen=True)
class Footprint:
    """One footprint of the board. kind: 'through_hole', 'smd', 'virtual' (no part: KiCad 5's
    virtual, KiCad 6's board_only) or 'other' (KiCad 6+ with neither type)."""
    reference: str
    library: str
    kind: str
    side: str                               # 'top' or 'bottom'
    models: tuple[Model, ...]
    line: int
    hidden: tuple[Model, ...] = field(default=())


def _numbers(node: Node | None, what: str, path: str, default: tuple) -> tuple:
    if node is None:
        return default
    xyz = node.child('xyz')
    values = xyz.atoms() if xyz is not None else node.atoms()
    try:
        out = tuple(float(v) for v in values)
    except ValueError:
        out = ()
    if len(out) != 3:
        raise InvalidArgument('board.pcb', path, f'line {node.line}: ({what} ...) must hold '
                              f'three numbers (xyz x y z), not {values}')
    return out


def _model(node: Node, path: str) -> tuple[Model, bool]:
    atoms = node.atoms()
    if not atoms:
        raise InvalidArgument('board.pcb', path, f'line {node.line}: (model) names no file')
    hide = node.child('hide')
    hidden = 'hide' in atoms[1:] or (hide is not None and hide.atoms()[:1] == ['yes'])
    offset = _numbers(node.child('offset'), 'offset', path, None)
    if offset is None:
        at = _numbers(node.child('at'), 'at', path, (0.0, 0.0, 0.0))
        offset = tuple(INCH * v for v in at)
    return Model(path=atoms[0], offset=offset,
                 scale=_numbers(node.child('scale'), 'scale', path, (1.0, 1.0, 1.0)),
                 rotate=_numbers(node.child('rotate'), 'rotate', path, (0.0, 0.0, 0.0)),
                 line=node.line), hidden


def _reference(node: Node) -> str:
    for text in node.children('fp_text'):
        atoms = text.atoms()
        if atoms[:1] == ['reference'] and len(atoms) > 1:
            return atoms[1]
    for prop in node.children('property'):
        atoms = prop.atoms()
        if atoms[:1] == ['Reference'] and len(atoms) > 1:
            return atoms[1]
    return ''


def _kind(node: Node, legacy: bool) -> str:
    attr = node.child('attr')
    flags = set(attr.atoms()) if attr is not None else set()
    if 'virtual' in flags or 'board_only' in flags:
        return 'virtual'
    if 'smd' in flags:
        return 'smd'
    if 'through_hole' in flags:
        return 'through_hole'
    # KiCad 5 writes no type for a through-hole footprint: one with a plated hole is one
    if legacy and any('thru_hole' in pad.atoms() for pad in node.children('pad')):
        return 'through_hole'
    return 'other'


def footprints(board: Node, path: str) -> list[Footprint]:
    """Every footprint of the board, in the file's order."""
    out = []
    for node in board.items:
        if not isinstance(node, Node) or node.head not in ('footprint', 'module'):
            continue
        legacy = node.head == 'module'
        library = (node.atoms() or [''])[0]
        layer = node.child('layer')
        side = 'bottom' if layer is not None and layer.atoms()[:1] == ['B.Cu'] else 'top'
        shown, hidden = [], []
        for m in node.children('model'):
            model, hide = _model(m, path)
            (hidden if hide else shown).append(model)
        out.append(Footprint(reference=_reference(node), library=library,
                             kind=_kind(node, legacy), side=side, models=tuple(shown),
                             line=node.line, hidden=tuple(hidden)))
    return out


def read(path: str) -> tuple[Node, list[Footprint]]:
    """The board file at `path` parsed, and its footprints. InvalidArgument for a file that
    cannot be read, is too large, or is not a whole KiCad board."""
    try:
        size = os.path.getsize(path)
        if size > MAX_BOARD_BYTES:
            raise InvalidArgument('board.pcb', path, f'is {size} bytes (limit {MAX_BOARD_BYTES})')
        with open(path, encoding='utf-8') as f:
            text = f.read()
    except OSError as exc:
        raise InvalidArgument('board.pcb', path, f'cannot be read: {exc.strerror or exc}'
                              ) from None
    except UnicodeDecodeError as exc:
        raise InvalidArgument('board.pcb', path, f'is not UTF-8 text: {exc}') from None
    board = parse(text, path)
    return board, footprints(board, path)


_VARIABLE = re.compile(r'\$\{([^}]*)\}|\$\(([^)]*)\)')


def resolve(written: str, board_dir: str, models: str | None,
            environ: Mapping[str, str]) -> tuple[str, str]:
    """A model's path as written, with KiCad's variables replaced: (path, '') or ('', why it
    cannot be resolved). `models`: the 3D library's folder for the library variables (None:
    the environment's value of each)."""
    missing = []

    def value(m: re.Match) -> str:
        name = m.group(1) or m.group(2)
        if name == 'KIPRJMOD':
            return board_dir
        if LIBRARY_VARIABLE.fullmatch(name) and models is not None:
            return models
        if name in environ:
            return environ[name]
        missing.append(name)
        return m.group(0)

    out = _VARIABLE.sub(value, written)
    if missing:
        return '', (f'its model path uses ${{{missing[0]}}}, which is not set: give board.models '
                     "(KiCad's 3D library folder) or set it in the environment")
    out = os.path.expanduser(out)
    if os.path.isabs(out):
        return os.path.normpath(out), ''
    # a path relative to neither: the board's folder first, then the 3D library's (KiCad's
    # FILENAME_RESOLVER::ResolvePath, common/filename_resolver.cpp: the project's folder,
    # then the partial path under ${KICAD<n>_3DMODEL_DIR}, "legacy behavior")
    beside = os.path.normpath(os.path.join(board_dir, out))
    library = models if models is not None else next(
        (v for k, v in sorted(environ.items()) if LIBRARY_VARIABLE.fullmatch(k)), None)
    if library and not (os.path.exists(beside) or step_beside(beside)):
        there = os.path.normpath(os.path.join(library, out))
        if os.path.exists(there) or step_beside(there):
            return there, ''
    return beside, ''


def step_beside(model_path: str) -> str:
    """The STEP file of a model: the file itself when it is STEP, else the file of the same
    name with a STEP suffix beside it; '' when there is none."""
    if model_path.endswith(STEP_SUFFIXES):
        return model_path if os.path.isfile(model_path) else ''
    stem = os.path.splitext(model_path)[0]
    return next((stem + s for s in STEP_SUFFIXES if os.path.isfile(stem + s)), '')
