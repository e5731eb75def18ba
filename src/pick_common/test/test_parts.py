"""Part models: built-in geometry and user meshes, good and degenerate (no physics: the
world's tests drop a user mesh)."""

import os
import warnings

from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
from pick_common.errors import InvalidArgument, MeshError
from pick_common.parts import pieces
from pick_common.parts.geometry import build_part
from pick_common.parts.meshes import MESH_EXTENT
from pick_common.parts.models import BUILTIN_MODELS
from pick_common.parts.primitives import Cylinder, Hull
from pick_common.parts.spec import PartSpec
import pytest
import trimesh

STEP = os.path.join(os.path.dirname(__file__), '..', '..', 'experiment_manager', 'config',
                    'parts', 'TO-220-3_Vertical.step')


@pytest.mark.parametrize('model', sorted(BUILTIN_MODELS))
def test_builtin_geometry_is_consistent(model):
    part = build_part(PartSpec(model=model))
    assert part.mass == BUILTIN_MODELS[model][1]
    assert part.volume > 0
    # The bounding sphere about `center` encloses the visual and the collision compound.
    assert np.linalg.norm(part.visual.vertices - part.center, axis=1).max() <= part.radius + 1e-9


def test_capacitor_dimensions_follow_the_parameters():
    part = build_part(PartSpec(dimensions={'body_diameter': 0.008, 'body_length': 0.016}))
    lo, hi = part.visual.bounds
    assert np.allclose(hi[:2] - lo[:2], [0.008, 0.008])
    assert np.isclose(hi[2] - lo[2], 0.016 + 0.015)
    body = part.primitives[0]
    assert isinstance(body, Cylinder) and (body.radius, body.length) == (0.004, 0.016)
    leads = 2 * np.pi * 0.00025**2 * 0.015
    assert np.isclose(part.volume, np.pi * 0.004**2 * 0.016 + leads, rtol=0.02)


def test_inconsistent_builtin_dimensions_are_refused():
    with pytest.raises(InvalidArgument, match='part.dimensions.lead_pitch'):
        build_part(PartSpec(dimensions={'lead_pitch': 0.01}))
    with pytest.raises(InvalidArgument, match='part.dimensions.pins_per_row: 2.5 is not an int'):
        build_part(PartSpec(model='dip', dimensions={'pins_per_row': 2.5}))
    with pytest.raises(InvalidArgument, match='part.dimensions.tab_thickness'):
        build_part(PartSpec(model='to220', dimensions={'tab_thickness': 0.01}))


def _two_body_mesh() -> trimesh.Trimesh:
    box = trimesh.creation.box(extents=[0.006, 0.004, 0.002])
    pin = trimesh.creation.cylinder(radius=0.0005, height=0.006)
    pin.apply_translation([0.0, 0.0, -0.004])
    return trimesh.util.concatenate([box, pin])


@pytest.mark.parametrize('suffix', ['stl', 'obj', 'ply'])
def test_user_mesh_becomes_convex_hulls(tmp_path, suffix):
    path = tmp_path / f'part.{suffix}'
    mesh = _two_body_mesh()
    mesh.apply_scale(1000.0)  # written in mm, read back with scale 0.001
    mesh.export(path)
    spec = PartSpec(model='mesh', mesh_path=str(path), scale=0.001, mass=0.0003)
    part = build_part(spec)
    assert [type(p) for p in part.primitives] == [Hull, Hull]
    assert np.isclose(part.volume, 0.006 * 0.004 * 0.002 + np.pi * 0.0005**2 * 0.006, rtol=0.05)


def _write(path, text):
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(('content', 'rule'), [
    (None, 'does not exist'),
    ('', 'could not be read|holds no triangles'),
    ('v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n', 'index 6 is out of bounds'),
    ('v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nv 0.01 0.01 0\nf 1 2 3\nf 2 4 3\n', 'zero volume'),
    ('v 0 0 0\nv nan 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n', 'non-finite'),
])
def test_degenerate_meshes_are_refused_before_pybullet(tmp_path, content, rule):
    path = str(tmp_path / 'missing.obj') if content is None else _write(tmp_path / 'p.obj',
                                                                        content)
    with pytest.raises(MeshError, match=f'part.mesh_path: .*({rule})'):
        build_part(PartSpec(model='mesh', mesh_path=path, mass=0.001))


def test_ply_with_face_indices_out_of_range_is_refused(tmp_path):
    ply = ('ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n'
           'property float z\nelement face 2\nproperty list uchar int vertex_indices\n'
           'end_header\n0 0 0\n0.01 0 0\n0 0.01 0\n0 0 0.01\n3 0 1 2\n3 0 2 9\n')
    path = _write(tmp_path / 'p.ply', ply)
    with pytest.raises(MeshError, match=r'part.mesh_path: .* has face indices outside \[0, 3\]'):
        build_part(PartSpec(model='mesh', mesh_path=path, mass=0.001))


def test_mesh_scale_and_mass_are_checked(tmp_path):
    path = tmp_path / 'part.stl'
    _two_body_mesh().export(path)
    with pytest.raises(InvalidArgument, match='part.mass: None is required for a mesh part'):
        build_part(PartSpec(model='mesh', mesh_path=str(path)))
    with pytest.raises(MeshError, match=r'is 6000 mm across at scale 1000; a part must be 0\.5 to '
                       r'300 mm across: in mm \(scale 0\.001\) it is 0\.006 mm|in m \(scale 1\)'):
        build_part(PartSpec(model='mesh', mesh_path=str(path), scale=1000.0, mass=0.001))
    with pytest.raises(InvalidArgument, match='part.scale: 0.0 must be > 0'):
        build_part(PartSpec(model='mesh', mesh_path=str(path), scale=0.0, mass=0.001))
    with pytest.raises(MeshError, match='part.mesh_path: .* is empty'):
        build_part(PartSpec(model='mesh', mass=0.001))


def test_a_step_file_is_read_in_metres_and_takes_no_scale():
    # KiCad's TO-220 states millimetres; trimesh (with cascadio) reads it in metres.
    part = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    assert part.visual.extents == pytest.approx((0.01025, 0.004455, 0.028525), abs=1e-6)
    with pytest.raises(MeshError, match=r'part\.scale: 0\.001 must be 1 for '
                       r'TO-220-3_Vertical\.step: the file states its units'):
        build_part(PartSpec(model='mesh', mesh_path=STEP, scale=0.001, mass=0.002))


def test_a_truncated_or_foreign_step_file_is_named_and_nothing_else_is_printed(tmp_path, capfd):
    with open(STEP, 'rb') as f:
        whole = f.read()
    cut = tmp_path / 'cut.step'
    cut.write_bytes(whole[:len(whole) // 3])
    with pytest.raises(MeshError) as err:
        build_part(PartSpec(model='mesh', mesh_path=str(cut), mass=0.002))
    text = str(err.value)
    assert text.startswith(f'part.mesh_path: {str(cut)!r} is not a readable STEP file: '
                           'OpenCASCADE says ')
    assert 'Line ' in text and 'truncated' in text
    assert 'converted' not in text and 'Errno' not in text       # nothing of our temporaries
    printed = capfd.readouterr()
    assert 'Failed to read STEP' not in printed.out + printed.err    # OpenCASCADE's own lines
    other = tmp_path / 'notes.step'
    other.write_text('solid part\nendsolid\n')
    with pytest.raises(MeshError, match="is not a STEP file: it does not begin with "
                       "ISO-10303-21; \\(it begins b'solid part"):
        build_part(PartSpec(model='mesh', mesh_path=str(other), mass=0.002))


@pytest.mark.parametrize('size, wrong', [(0.0004, True), (0.0006, False), (0.29, False),
                                         (0.31, True)])
def test_a_mesh_part_outside_sane_sizes_is_refused(tmp_path, size, wrong):
    path = str(tmp_path / 'box.stl')
    trimesh.creation.box((size, size / 2, size / 2)).export(path)
    spec = PartSpec(model='mesh', mesh_path=path, mass=0.001)
    if wrong:
        with pytest.raises(MeshError, match=f'is {size * 1000:g} mm across at scale 1'):
            build_part(spec)
    else:
        assert build_part(spec).visual.extents.max() == pytest.approx(size)


_coordinate = st.one_of(st.floats(-0.02, 0.02), st.sampled_from(
    [0.0, np.nan, np.inf, -np.inf, 1e300, -1e-300, 1e6]))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                    HealthCheck.function_scoped_fixture])
@given(vertices=st.lists(st.tuples(_coordinate, _coordinate, _coordinate), min_size=0,
                         max_size=12),
       faces=st.lists(st.tuples(*[st.integers(-2, 14)] * 3), min_size=0, max_size=16),
       suffix=st.sampled_from(['.obj', '.stl', '.ply']))
def test_broken_meshes_get_a_mesh_error_or_a_sane_part(tmp_path, vertices, faces, suffix):
    """Whatever is in the file, the loader says what is wrong with it (MeshError) or returns a
    part whose geometry is finite and of sane size: never another exception, never a NaN."""
    path = tmp_path / f'broken{suffix}'
    if suffix == '.obj':
        text = ''.join(f'v {x!r} {y!r} {z!r}\n' for x, y, z in vertices)
        text += ''.join(f'f {a + 1} {b + 1} {c + 1}\n' for a, b, c in faces)
        path.write_text(text)
    else:
        try:
            trimesh.Trimesh(np.array(vertices, dtype=float).reshape(-1, 3),
                            np.array(faces, dtype=np.int64).reshape(-1, 3),
                            process=False).export(path)
        except Exception:       # a file trimesh cannot even write: write bytes of it
            path.write_bytes(b'solid x\nendsolid x\n' if suffix == '.stl' else b'ply\n')
    try:
        part = build_part(PartSpec(model='mesh', mesh_path=str(path), mass=0.001))
    except MeshError:
        return
    assert np.isfinite(part.visual.vertices).all() and part.volume > 0
    assert MESH_EXTENT[0] <= part.visual.extents.max() <= MESH_EXTENT[1]
    for p in part.primitives:
        assert np.isfinite(p.vertices).all()


def test_a_closed_mesh_turned_inside_out_is_turned_back(tmp_path):
    box = trimesh.creation.box((0.006, 0.004, 0.002))
    box.invert()
    box.export(tmp_path / 'inverted.stl')
    part = build_part(PartSpec(model='mesh', mesh_path=str(tmp_path / 'inverted.stl'),
                               mass=0.001))
    assert part.volume == pytest.approx(0.006 * 0.004 * 0.002, rel=1e-6)


def test_a_step_file_and_its_stl_in_mm_are_the_same_part(tmp_path):
    step = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    mesh = step.visual.copy()
    mesh.apply_scale(1000.0)                        # written out in mm, as CAD tools export
    mesh.export(tmp_path / 'to220.stl')
    stl = build_part(PartSpec(model='mesh', mesh_path=str(tmp_path / 'to220.stl'),
                              scale=0.001, mass=0.002))
    assert stl.volume == pytest.approx(step.volume, rel=1e-6)
    assert stl.mass_frame[0] == pytest.approx(step.mass_frame[0], abs=1e-9)
    assert [len(p.vertices) for p in stl.primitives] == [len(p.vertices) for p in step.primitives]


def test_a_concave_part_is_cut_into_convex_pieces_that_fit_it():
    # KiCad's TO-220: a tab with a hole over a body, three leads below. Its one hull holds
    # 852 mm^3 over 487 mm^3 of part; CoACD's pieces fit it within a few per cent.
    part = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    together = sum(trimesh.convex.convex_hull(p.vertices).volume for p in part.primitives)
    assert len(part.primitives) > 3
    assert together == pytest.approx(part.volume, rel=0.05)
    assert max(len(p.vertices) for p in part.primitives) <= pieces.MAX_PIECE_VERTICES
    assert 'CoACD' in part.collision_note


def test_a_part_of_many_bodies_shares_its_pieces_out_rather_than_becoming_one_hull():
    # The TO-220's concave body (cut alone: more than 4 pieces) beside 28 small boxes: the 28
    # boxes leave it 4 of the 32 pieces, so it is cut again into at most 4 (a D-sub's shell
    # beside its other bodies was one hull of the whole part, 81 % over its volume)
    from pick_common.parts.meshes import load_mesh
    to220 = load_mesh(STEP, 1.0)
    alone, _ = pieces.convex_cover(to220, STEP)
    boxes = [trimesh.creation.box((0.001,) * 3).apply_translation((0.03 + 0.002 * i, 0.03, 0))
             for i in range(28)]
    mesh = trimesh.util.concatenate([to220, *boxes])
    hulls, words = pieces.convex_cover(mesh, 'many.stl')
    assert len(alone) > 4 and len(hulls) == 28 + 4
    assert 'at most 4 each' in words and 'one convex hull' not in words
    together = sum(h.volume for h in hulls) - 28 * 1e-9
    assert to220.volume < together < trimesh.convex.convex_hull(to220.vertices).volume


def test_a_flat_closed_body_is_left_out_without_a_numpy_warning():
    # KiCad's electrolytic capacitors' models hold closed bodies of no volume (two-triangle
    # slivers in CP_Radial_D10.0mm and CP_Axial_L10.0mm): trimesh divides by the
    # volume for the mass centre, and numpy's "invalid value encountered in divide" reached
    # the user's terminal on every run of a board with one
    box = trimesh.creation.box((0.004, 0.004, 0.002))
    flat = trimesh.Trimesh([[0.01, 0, 0], [0.012, 0, 0], [0.01, 0.002, 0], [0.011, 0.001, 0]],
                           [[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]], process=False)
    assert flat.is_watertight
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        hulls, _ = pieces.convex_cover(trimesh.util.concatenate([box, flat]), 'flat.stl')
    assert len(hulls) == 1 and hulls[0].volume == pytest.approx(box.volume)


def test_pieces_much_larger_than_the_part_are_said_with_why():
    # within the 15 % allowance nothing is said; beyond it, the threshold that fills hollows
    assert pieces.why_larger(1.14e-6, 1.0e-6) == ''
    said = pieces.why_larger(1.6e-6, 1.0e-6)
    assert said.startswith('more than 15 % over the part') and '0.05' in said
    assert 'open body' in said


def test_convex_and_open_bodies_keep_their_hulls_and_say_so(tmp_path):
    trimesh.creation.box((0.006, 0.004, 0.002)).export(tmp_path / 'box.stl')
    box = build_part(PartSpec(model='mesh', mesh_path=str(tmp_path / 'box.stl'), mass=0.001))
    assert len(box.primitives) == 1 and box.collision_note.startswith('1 convex closed body')
    open_mesh = trimesh.load(STEP, force='mesh')
    open_mesh = trimesh.Trimesh(open_mesh.vertices, open_mesh.faces[5:])   # five triangles gone
    open_mesh.export(tmp_path / 'open.stl')
    part = build_part(PartSpec(model='mesh', mesh_path=str(tmp_path / 'open.stl'), mass=0.002))
    assert 'open body' in part.collision_note and 'close the mesh' in part.collision_note


def test_pieces_come_from_the_cache_the_same_as_computed(tmp_path, monkeypatch):
    monkeypatch.setenv('PICK_SIM_CACHE', str(tmp_path))
    first = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    assert len(os.listdir(tmp_path / 'pieces')) == 2            # the entry and the lock

    def _no(body, most):
        raise AssertionError('decomposed again: the cache was not read')
    monkeypatch.setattr(pieces, '_decompose', _no)
    again = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    assert len(again.primitives) == len(first.primitives)
    for a, b in zip(first.primitives, again.primitives, strict=True):
        assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
    # computed afresh in another cache: the same pieces (CoACD is seeded, the pieces sorted)
    monkeypatch.undo()
    monkeypatch.setenv('PICK_SIM_CACHE', str(tmp_path / 'other'))
    fresh = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    for a, b in zip(first.primitives, fresh.primitives, strict=True):
        assert np.array_equal(a.vertices, b.vertices)
