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
from pick_common.parts.insets import inset_hull
from pick_common.parts.materials import BodyValues
from pick_common.parts.primitives import Box, Cylinder
from pick_common.states import quaternion_multiply, rotate
import pybullet as pb
import trimesh

from .config import GRAVITY, PhysicsConfig, solver_iterations

INSTANCE_GAP = 0.05             # m between the outer walls of neighbouring instances
TRAY_MASS = 3.0                 # kg; the tray is a dynamic body whose motion is prescribed


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


def create_part_shape(client: int, part: PartGeometry, directory: str) -> int:
    """The part's collision compound as one PyBullet shape. Convex hulls are inset (insets:
    pybullet's margin taken off) and written as OBJ files into `directory` (pybullet takes
    hull vertices only from a file, one hull each)."""
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
