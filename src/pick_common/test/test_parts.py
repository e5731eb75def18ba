"""Part models: built-in geometry and user meshes, good and degenerate (no physics: the
world's tests drop a user mesh)."""

import numpy as np
from pick_common.errors import InvalidArgument, MeshError
from pick_common.parts import build_part, BUILTIN_MODELS, PartSpec
import pytest
import trimesh


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
    assert body.kind == 'cylinder' and body.size == (0.004, 0.016)
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
    assert [p.kind for p in part.primitives] == ['hull', 'hull']
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
    with pytest.raises(MeshError, match='check part.scale'):
        build_part(PartSpec(model='mesh', mesh_path=str(path), scale=1000.0, mass=0.001))
    with pytest.raises(InvalidArgument, match='part.scale: 0.0 must be > 0'):
        build_part(PartSpec(model='mesh', mesh_path=str(path), scale=0.0, mass=0.001))
    with pytest.raises(MeshError, match='part.mesh_path: .* is empty'):
        build_part(PartSpec(model='mesh', mass=0.001))
