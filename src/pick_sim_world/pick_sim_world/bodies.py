"""Building a PyBullet scene: the engine's settings, the part's collision shape, containers
(a static bin, or a tray whose motion tray.py prescribes) and part bodies.

Every function takes the PyBullet client it works on; the World owns the client.
"""

from collections.abc import Mapping, Sequence
import hashlib
import os

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.parts.geometry import PartGeometry
from pick_common.parts.materials import BodyValues
from pick_common.parts.primitives import Box, Cylinder, Hull
from pick_common.states import quaternion_multiply, rotate
import pybullet as pb
from scipy.optimize import linprog
from scipy.spatial import HalfspaceIntersection
import trimesh

from .config import GRAVITY, PhysicsConfig, solver_iterations

INSTANCE_GAP = 0.05             # m between the outer walls of neighbouring instances
TRAY_MASS = 3.0                 # kg; the tray is a dynamic body whose motion is prescribed
# Bullet collides a convex hull grown by its collision margin, and pybullet gives every hull
# of a compound 1 mm (URDF and shape importers' fixed default; changeDynamics' collisionMargin
# sets only the compound's own, measured: a hull's bounds do not move), which made every mesh
# part 2 mm larger in the physics than in the checks. Each hull is inset by the margin, so that
# hull + margin is the part's surface again, its edges rounded by 1 mm; a piece thinner than
# 2 mm can be inset only by INSET_SHARE of the largest ball inside it and stays swollen by the
# rest (hull_swelling).
HULL_MARGIN = 1e-3              # m, pybullet's margin of a compound's convex hull
INSET_SHARE = 0.45              # of a piece's inner diameter: the most it is inset


def instance_seed(seed: int, index: int) -> int:
    """The seed of instance `index` derived from the scene's base seed (stable across runs)."""
    return int(np.random.SeedSequence([seed, index]).generate_state(1, np.uint64)[0])


def instance_pitch(spec: ContainerSpec) -> float:
    """Distance along x between the origins of neighbouring instances, m."""
    return containers.outer_size(spec)[0] + INSTANCE_GAP


def configure(client: int, physics: PhysicsConfig, kind: str) -> None:
    """Empty the simulation and set gravity and the solver settings for containers of `kind`."""
    pb.resetSimulation(physicsClientId=client)
    pb.setGravity(0.0, 0.0, -GRAVITY, physicsClientId=client)
    pb.setPhysicsEngineParameter(
        fixedTimeStep=physics.time_step,
        numSolverIterations=solver_iterations(physics, kind),
        warmStartingFactor=physics.warm_starting_factor,
        contactBreakingThreshold=physics.contact_breaking_threshold,
        deterministicOverlappingPairs=1, physicsClientId=client)


def hull_inset(vertices: np.ndarray, faces: np.ndarray) -> float:
    """How far a hull is inset, m: HULL_MARGIN, or INSET_SHARE of the diameter of the largest
    ball inside it when that is less."""
    return _inset(vertices, faces)[3]


def hull_swelling(part: PartGeometry) -> float:
    """How far the physics' surface of a part lies outside its geometry at most, m: 0 when
    every hull is inset by the whole margin (and for boxes and cylinders, whose margins
    Bullet keeps inside their extents)."""
    return max((HULL_MARGIN - hull_inset(p.vertices, p.faces) for p in part.primitives
                if isinstance(p, Hull)), default=0.0)


def _planes(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The hull's face planes: unit outward normals (F, 3) and offsets (F,), n.x <= d inside;
    faces of no area left out."""
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    cross = mesh.triangles_cross
    area = np.linalg.norm(cross, axis=1)
    keep = area > 1e-12 * max(area.max(), 1e-300)
    normals = cross[keep] / area[keep, None]
    if mesh.volume < 0:          # faces wound inwards
        normals = -normals
    return normals, np.einsum('ij,ij->i', normals, mesh.triangles[keep, 0])


def _inset(vertices: np.ndarray, faces: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The hull's face planes (normals, offsets: _planes), the centre of the largest ball
    inside it (its Chebyshev centre: a linear programme over the planes) and how far the hull
    is inset (hull_inset), from one pass over its faces."""
    normals, offsets = _planes(vertices, faces)
    # maximise r: n.c + r <= d for every face
    rows = np.column_stack([normals, np.ones(len(normals))])
    ball = linprog(c=[0.0, 0.0, 0.0, -1.0], A_ub=rows, b_ub=offsets,
                   bounds=[(None, None)] * 3 + [(0.0, None)], method='highs').x
    return normals, offsets, ball[:3], min(HULL_MARGIN, INSET_SHARE * 2.0 * float(ball[3]))


def inset_hull(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The vertices of the convex hull whose faces lie hull_inset inside those of the hull
    (vertices (K, 3), triangles faces), so that Bullet's hull grown by its margin is the hull
    (short of hull_swelling)."""
    normals, offsets, centre, margin = _inset(vertices, faces)
    inside = HalfspaceIntersection(np.column_stack([normals, -(offsets - margin)]), centre)
    return inside.intersections


def create_part_shape(client: int, part: PartGeometry, directory: str) -> int:
    """The part's collision compound as one PyBullet shape. Convex hulls are inset by
    hull_inset and written as OBJ files into `directory` (pybullet takes hull vertices only
    from a file, one hull each)."""
    kinds, radii, lengths, halves, files, positions, orientations = [], [], [], [], [], [], []
    for p in part.primitives:
        radius = length = 0.0
        half = [0.0, 0.0, 0.0]
        path = ''
        if isinstance(p, Box):
            kind, half = pb.GEOM_BOX, list(p.half)
        elif isinstance(p, Cylinder):
            kind, radius, length = pb.GEOM_CYLINDER, p.radius, p.length
        else:
            kind = pb.GEOM_MESH
            hull = trimesh.convex.convex_hull(inset_hull(p.vertices, p.faces))
            # named by its content: pybullet keeps a file's mesh by its path for the life of
            # the process, resets included, so a reused name would bring back an old part
            digest = hashlib.sha256(hull.vertices.tobytes() + hull.faces.tobytes())
            path = os.path.join(directory, f'hull_{digest.hexdigest()[:20]}.obj')
            hull.export(path)
        kinds.append(kind)
        radii.append(radius)
        lengths.append(length)
        halves.append(half)
        files.append(path)
        positions.append(list(p.position))
        orientations.append(list(p.orientation))
    return pb.createCollisionShapeArray(
        kinds, radii=radii, lengths=lengths, halfExtents=halves, fileNames=files,
        meshScales=[[1.0, 1.0, 1.0]] * len(kinds), collisionFramePositions=positions,
        collisionFrameOrientations=orientations, physicsClientId=client)


def create_container(client: int, spec: ContainerSpec, origin: np.ndarray,
                     surface: BodyValues) -> int:
    """The container's body at `origin` (world frame, m): a static bin, or a tray of TRAY_MASS
    whose state tray.TrayDrive prescribes before every step (so parts feel its velocity); its
    coefficients `surface` (materials.body_values: with the part's, the file's pairs)."""
    boxes = containers.wall_boxes(spec)
    shape = pb.createCollisionShapeArray(
        [pb.GEOM_BOX] * len(boxes), halfExtents=[list(h) for h, _ in boxes],
        collisionFramePositions=[list(p) for _, p in boxes], physicsClientId=client)
    mass = 0.0 if spec.kind == containers.BIN else TRAY_MASS
    body = pb.createMultiBody(mass, shape, basePosition=origin.tolist(),
                              useMaximalCoordinates=True, physicsClientId=client)
    pb.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0,
                      activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING,
                      physicsClientId=client, **_coefficients(surface))
    return body


def _coefficients(values: BodyValues) -> dict[str, float]:
    return {'lateralFriction': values.lateral_friction,
            'rollingFriction': values.rolling_friction,
            'spinningFriction': values.spinning_friction, 'restitution': values.restitution}


def create_part(client: int, shape: int, part: PartGeometry, pose: np.ndarray,
                values: BodyValues) -> int:
    """A part body of `shape` at `pose` (7,) in the world frame, with the part's coefficients
    `values` (materials.body_values).

    No continuous collision detection: Bullet sweeps only convex shapes
    (btDiscreteDynamicsWorld's createPredictiveContactsInternal and integrateTransformsInternal
    test isConvex()), and a part is a compound, so a swept sphere changed no pose (tested bit
    for bit, world README "Thrown parts"). Streamed drops keep falls short instead, and the
    world reports parts that tunnel or are thrown."""
    inertial = {}
    if part.mass_frame is not None:     # a mesh's own mass centre and principal axes
        centre, axes = part.mass_frame
        inertial = {'baseInertialFramePosition': centre.tolist(),
                    'baseInertialFrameOrientation': axes.tolist()}
    body = pb.createMultiBody(part.mass, shape, basePosition=pose[:3].tolist(),
                              baseOrientation=pose[3:].tolist(), useMaximalCoordinates=True,
                              physicsClientId=client, **inertial)
    pb.changeDynamics(body, -1, activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING,
                      physicsClientId=client, **_coefficients(values))
    return body


def part_frame_poses(poses: np.ndarray, part: PartGeometry) -> np.ndarray:
    """The poses (N, 7) of a part's own frame from PyBullet's base poses, which are of its mass
    centre's frame (part.mass_frame); the same poses for a built-in model."""
    if part.mass_frame is None or not len(poses):
        return poses
    centre, axes = part.mass_frame
    out = poses.copy()
    # frame = base * inverse(inertial): orientation q_base * conj(q_axes), then back off the
    # mass centre along the frame's axes
    out[:, 3:] = quaternion_multiply(poses[:, 3:], axes * np.array([-1.0, -1.0, -1.0, 1.0]))
    out[:, :3] = poses[:, :3] - rotate(out[:, 3:], centre)
    return out


def part_centres(poses: np.ndarray, part: PartGeometry) -> np.ndarray:
    """Centres (N, 3) of the parts' enclosing spheres (part.center) for part-frame `poses`
    (N, 7), in the poses' frame, m."""
    return poses[:, :3] + rotate(poses[:, 3:], part.center)


def base_poses(client: int, bodies: list[int]) -> np.ndarray:
    """World-frame poses (N, 7) of bodies, xyz + xyzw."""
    poses = np.empty((len(bodies), 7))
    for row, body in enumerate(bodies):
        position, orientation = pb.getBasePositionAndOrientation(body, physicsClientId=client)
        poses[row, :3] = position
        poses[row, 3:] = orientation
    return poses


def bodies_near(client: int, body: int, reach: float) -> list[int]:
    """The bodies whose bounding boxes come within `reach` (m) of `body`'s (itself included)."""
    low, high = pb.getAABB(body, physicsClientId=client)
    near = pb.getOverlappingObjects(np.subtract(low, reach).tolist(),
                                    np.add(high, reach).tolist(), physicsClientId=client)
    return [b for b, _ in near or ()]


def max_penetration(client: int) -> float:
    """The deepest overlap of any two bodies in contact now, m (0 when none overlap)."""
    contacts = pb.getContactPoints(physicsClientId=client)
    return max(0.0, -min((c[8] for c in contacts), default=0.0))


def touching(client: int, bodies: Sequence[int]) -> set[int]:
    """The bodies that a body of `bodies` touches (is within the contact-breaking threshold
    of), by the contacts of the last step; `bodies` themselves among them only where two of
    them touch."""
    found = set()
    for body in bodies:
        found.update(contact[2] for contact in pb.getContactPoints(bodyA=body,
                                                                   physicsClientId=client))
    return found


def parts_touching(client: int, bodies_of: Mapping[int, int], ids: list[int]) -> set[int]:
    """The parts not in `ids` that a part of `ids` touches (touching); `bodies_of`: part id ->
    body."""
    part_of = {body: pid for pid, body in bodies_of.items() if pid not in ids}
    touched = touching(client, [bodies_of[pid] for pid in ids])
    return {part_of[b] for b in touched if b in part_of}
