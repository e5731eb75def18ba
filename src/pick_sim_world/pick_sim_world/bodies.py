"""Building a PyBullet scene: the engine's settings, the part's collision shape, containers
(a static bin, or a tray whose motion tray.py prescribes) and part bodies, and the queries of
the scene's bodies the world asks.

Every function takes the Engine (engine.py, SI units) it works on; the World owns it.
"""

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.parts.geometry import PartGeometry
from pick_common.parts.insets import inset_hull
from pick_common.parts.materials import BodyValues
from pick_common.parts.primitives import box, Hull
from pick_common.specs import SceneSpec
from pick_common.states import quaternion_multiply, rotate
import trimesh

from .config import GRAVITY, PhysicsConfig, solver_iterations
from .engine import Engine

INSTANCE_GAP = 0.05             # m between the outer walls of neighbouring instances
TRAY_MASS = 3.0                 # kg; the tray is a dynamic body whose motion is prescribed



@dataclass
class Instance:
    """One instance: container body, origin in the world (m), its generator and its parts."""

    id: int
    seed: int
    origin: np.ndarray
    body: int
    rng: np.random.Generator
    part_ids: list[int] = field(default_factory=list)

def instance_seed(seed: int, index: int) -> int:
    """The seed of instance `index` derived from the scene's base seed (stable across runs)."""
    return int(np.random.SeedSequence([seed, index]).generate_state(1, np.uint64)[0])


def instance_pitch(spec: ContainerSpec) -> float:
    """Distance along x between the origins of neighbouring instances, m."""
    return containers.outer_size(spec)[0] + INSTANCE_GAP


def configure(engine: Engine, physics: PhysicsConfig, kind: str) -> None:
    """Empty the simulation and set gravity and the solver settings for containers of `kind`."""
    engine.reset(GRAVITY, physics.time_step, solver_iterations(physics, kind),
                 physics.warm_starting_factor, physics.contact_breaking_threshold)


def create_part_shape(engine: Engine, part: PartGeometry, directory: str) -> int:
    """The part's collision compound as one shape, in the frame of its body: a mesh part's
    mass centre and principal axes (part.mass_frame), a built-in's own frame. So nothing of
    the file's frame reaches the physics: Bullet's contact-breaking threshold grows with a
    piece's distance from its body's origin (getAngularMotionDisc), and Bullet's inertia
    estimate follows the frame's axes. Convex hulls are inset by the engine's hull margin
    (insets), so that the hull the engine grows by its margin is the part's surface; their
    file goes into `directory` (Engine.shape)."""
    margin = engine.hull_margin
    to_body = np.eye(4)
    if part.mass_frame is not None:
        centre, axes = part.mass_frame
        rotation = trimesh.transformations.quaternion_matrix([axes[3], *axes[:3]])[:3, :3]
        to_body[:3, :3], to_body[:3, 3] = rotation.T, -rotation.T @ centre
    pieces = []
    for p in part.primitives:
        if isinstance(p, Hull):
            hull = trimesh.convex.convex_hull(inset_hull(p.vertices, p.faces, margin))
            hull.apply_transform(to_body)
            pieces.append(Hull(np.asarray(hull.vertices, dtype=np.float64),
                               np.asarray(hull.faces, dtype=np.int64)))
        else:       # a built-in's box or cylinder, in its own frame (its body's)
            pieces.append(p)
    return engine.shape(pieces, directory)


def create_container(engine: Engine, spec: ContainerSpec, origin: np.ndarray,
                     surface: BodyValues) -> int:
    """The container's body at `origin` (world frame, m): a static bin, or a tray of TRAY_MASS
    whose state tray.TrayDrive prescribes before every step (so parts feel its velocity); its
    coefficients `surface` (materials.body_values: with the part's, the file's pairs)."""
    shape = engine.shape([box(h, p) for h, p in containers.wall_boxes(spec)])
    mass = 0.0 if spec.kind == containers.BIN else TRAY_MASS
    body = engine.body(mass, shape, origin)
    engine.set_contact(body, surface, damping=0.0)
    return body


def create_instances(engine: Engine, scene: SceneSpec, surface: BodyValues) -> list[Instance]:
    """The scene's instances side by side along x, each with its container body and its own
    generator (seeded by instance_seed), no parts yet."""
    pitch = instance_pitch(scene.container)
    out = []
    for k in range(scene.instance_count):
        origin = np.array([k * pitch, 0.0, 0.0])
        seed = instance_seed(scene.seed, k)
        out.append(Instance(k, seed, origin, create_container(engine, scene.container, origin,
                                                              surface),
                            np.random.default_rng(seed)))
    return out


def create_part(engine: Engine, shape: int, part: PartGeometry, pose: np.ndarray,
                values: BodyValues) -> int:
    """A part body of `shape` at `pose` (7,) in the world frame, with the part's coefficients
    `values` (materials.body_values).

    No continuous collision detection: Bullet sweeps only convex shapes
    (btDiscreteDynamicsWorld's createPredictiveContactsInternal and integrateTransformsInternal
    test isConvex()), and a part is a compound, so a swept sphere changed no pose (tested bit
    for bit, world README "Thrown parts"). Streamed drops keep falls short instead, and the
    world reports parts that tunnel or are thrown."""
    base = body_poses(pose[None], part)[0]
    body = engine.body(part.mass, shape, base[:3], base[3:], part.moments)
    engine.set_contact(body, values)
    return body


def body_poses(poses: np.ndarray, part: PartGeometry) -> np.ndarray:
    """The poses (N, 7) of the parts' bodies, which are of a mesh part's mass centre's frame
    (part.mass_frame), from poses of the part's own frame; the same poses for a built-in
    model. The inverse of part_frame_poses."""
    if part.mass_frame is None or not len(poses):
        return poses
    centre, axes = part.mass_frame
    out = poses.copy()
    out[:, :3] = poses[:, :3] + rotate(poses[:, 3:], centre)
    out[:, 3:] = quaternion_multiply(poses[:, 3:], axes)
    return out


def part_frame_poses(poses: np.ndarray, part: PartGeometry) -> np.ndarray:
    """The poses (N, 7) of a part's own frame from its bodies' poses (body_poses); the same
    poses for a built-in model."""
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


def max_penetration(engine: Engine) -> float:
    """The deepest overlap of any two bodies in contact now, m (0 when none overlap)."""
    return max(0.0, -min((d for _, _, d in engine.contacts()), default=0.0))


def touching(engine: Engine, bodies: Sequence[int]) -> set[int]:
    """The bodies that a body of `bodies` touches (is within the contact-breaking threshold
    of), by the contacts of the last step; `bodies` themselves among them only where two of
    them touch."""
    found = set()
    for body in bodies:
        found.update(other for _, other, _ in engine.contacts(body))
    return found


def parts_touching(engine: Engine, bodies_of: Mapping[int, int], ids: list[int]) -> set[int]:
    """The parts not in `ids` that a part of `ids` touches (touching); `bodies_of`: part id ->
    body."""
    part_of = {body: pid for pid, body in bodies_of.items() if pid not in ids}
    touched = touching(engine, [bodies_of[pid] for pid in ids])
    return {part_of[b] for b in touched if b in part_of}
