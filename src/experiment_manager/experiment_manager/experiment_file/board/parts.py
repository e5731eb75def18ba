"""A board's parts: its footprints grouped by 3D model, one part per distinct model (the same
file at the same offset, scale and rotation), with its references and quantity per board,
and what becomes of it: decided (through-hole, its STEP file found), not decided (SMD:
tape-fed, not inserted) or refused with the reason (no model, a model path that does not
resolve or exist, no STEP beside the `.wrl`, a scale KiCad stretches unevenly). Virtual
footprints (no part) are left out."""

from collections.abc import Mapping
from dataclasses import dataclass
import os
import re

from pick_common.errors import InvalidArgument

from . import kicad

DECIDE = 'decide'                   # a through-hole part whose STEP file is found
NOT_THROUGH_HOLE = 'not through-hole'
REFUSED = 'refused'


@dataclass(frozen=True)
class BoardPart:
    """One distinct part of the board. `model`: its first footprint's model (as written);
    `step`: the STEP file read ('' unless status is DECIDE); `name`: a short id from the
    model's file name (the library's name for a footprint without a model)."""
    name: str
    references: tuple[str, ...]
    status: str
    reason: str = ''
    model: kicad.Model | None = None
    step: str = ''
    library: str = ''
    line: int = 0

    @property
    def quantity(self) -> int:
        return len(self.references)


def _natural(reference: str) -> tuple:
    """R2 before R10."""
    return tuple(int(t) if t.isdigit() else t for t in re.split(r'(\d+)', reference))


def _name(text: str) -> str:
    base = os.path.splitext(os.path.basename(text.split(':')[-1]))[0]
    return re.sub(r'[^A-Za-z0-9_.-]+', '_', base) or 'part'


def _status(fp: kicad.Footprint, board_dir: str, models: str | None,
            environ: Mapping[str, str]) -> tuple[str, str, str]:
    """(status, reason, STEP file) of one footprint."""
    if fp.kind == 'smd':
        return NOT_THROUGH_HOLE, 'an SMD footprint: placed from tape, not inserted', ''
    if fp.kind != 'through_hole':
        return NOT_THROUGH_HOLE, ("neither through-hole nor SMD in the board (KiCad's "
                                  "footprint type 'other')"), ''
    if not fp.models:
        why = 'its only 3D model is hidden' if fp.hidden else 'its footprint names no 3D model'
        return REFUSED, why, ''
    model = fp.models[0]
    if not all(abs(s - model.scale[0]) <= 1e-9 * abs(model.scale[0]) for s in model.scale) \
            or model.scale[0] <= 0:
        return REFUSED, (f'its model is scaled by {list(model.scale)} in the board: only an even, '
                         'positive scale keeps its shape'), ''
    path, why = kicad.resolve(model.path, board_dir, models, environ)
    if why:
        return REFUSED, why, ''
    step = kicad.step_beside(path)
    if step:
        return DECIDE, '', step
    if not os.path.exists(path):
        also = ('' if os.path.isabs(os.path.expanduser(model.path)) or '$' in model.path
                else ", nor under the 3D library's folder")
        return REFUSED, f'its model {path} does not exist{also} (board line {model.line})', ''
    return REFUSED, (f'its model {os.path.basename(path)} has no STEP file beside it: the '
                     'physics reads solids from STEP (a .wrl holds triangles and colours '
                     'only)'), ''


def board_parts(footprints: list[kicad.Footprint], board_dir: str, models: str | None,
                environ: Mapping[str, str], path: str = '') -> list[BoardPart]:
    """The board's distinct parts, through-hole ones first in the order of their first
    footprint, then the others. InvalidArgument naming `path` when no footprint is
    through-hole."""
    groups: dict[tuple, dict] = {}
    for fp in footprints:
        if fp.kind == 'virtual':
            continue
        status, reason, step = _status(fp, board_dir, models, environ)
        model = fp.models[0] if fp.models else None
        if model is not None:
            key = (status, step or model.path, model.offset, model.scale, model.rotate, reason)
        else:
            key = (status, fp.library, reason)
        group = groups.setdefault(key, {
            'name': _name(model.path if model is not None else fp.library), 'references': [],
            'status': status, 'reason': reason, 'model': model, 'step': step,
            'library': fp.library, 'line': fp.line})
        group['references'].append(fp.reference or f'(no reference, line {fp.line})')
    if not any(fp.kind == 'through_hole' for fp in footprints):
        kinds = sorted({fp.kind for fp in footprints})
        raise InvalidArgument('board.pcb', path, f'has no through-hole footprint (its '
                              f'{len(footprints)} footprint(s): {", ".join(kinds) or "none"}): '
                              'nothing for a robot to insert')
    parts = [BoardPart(**{**g, 'references': tuple(sorted(g['references'], key=_natural))})
             for g in groups.values()]
    order = {DECIDE: 0, REFUSED: 1, NOT_THROUGH_HOLE: 2}
    parts.sort(key=lambda p: order[p.status])
    # one name per part: a model used at two offsets or rotations gets a suffix
    seen: dict[str, int] = {}
    out = []
    for p in parts:
        seen[p.name] = seen.get(p.name, 0) + 1
        out.append(p if seen[p.name] == 1 else
                   BoardPart(**{**p.__dict__, 'name': f'{p.name}-{seen[p.name]}'}))
    return out
