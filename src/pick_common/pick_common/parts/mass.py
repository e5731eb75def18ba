"""The mass properties of a part's solid at uniform density: the physics' mass centre and
principal axes of a mesh part, wherever its file puts its origin."""

import numpy as np
import trimesh


def mass_properties(solids: list[trimesh.Trimesh], mass: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mass centre (3,), principal axes (4,) xyzw and principal moments (3,) kg m^2 of `mass`
    spread uniformly over `solids` (watertight meshes, in one frame; where they overlap the
    overlap counts twice)."""
    volumes = np.array([m.volume for m in solids])
    centres = np.array([m.center_mass for m in solids])
    centre = (volumes[:, None] * centres).sum(axis=0) / volumes.sum()
    tensor = np.zeros((3, 3))
    for m, v, c in zip(solids, volumes, centres, strict=True):
        d = c - centre          # trimesh's moment_inertia: about the solid's own centre, density 1
        tensor += np.asarray(m.moment_inertia) + v * ((d @ d) * np.eye(3) - np.outer(d, d))
    tensor *= mass / volumes.sum()
    moments, axes = np.linalg.eigh(tensor)
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    w, x, y, z = trimesh.transformations.quaternion_from_matrix(
        np.vstack([np.hstack([axes, np.zeros((3, 1))]), [0.0, 0.0, 0.0, 1.0]]))
    return centre, np.array([x, y, z, w]), np.maximum(moments, 0.0)
