"""The reference check: every part, every tilt, every other part, FCL for every decision, no
broadphase, no bounds and no caching. `validity.Validator.check` must give identical results
(its tests and bench/validity/bench_validity.py compare them); far slower."""

from collections.abc import Iterable, Sequence
import math
import time

import fcl
import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from scipy.spatial.transform import Rotation

from .check_geometry import CheckGeometry
from .geometry import collide, quaternions_to_matrices
from .results import (
    CENTRE_TOLERANCE,
    check_poses,
    PartResult,
    Report,
    STAGE_CANDIDACY,
    STAGE_CONTAINER,
    STAGE_NEIGHBOUR,
    STAGE_OUTSIDE,
    STAGE_PLACEABILITY,
    STAGE_VALID,
    target_rows,
    TIE,
)


def naive_check(geometry: CheckGeometry, container: ContainerSpec, ids: Sequence[int],
                poses: np.ndarray, targets: Iterable[int] | None = None,
                neighbour_check: bool = True) -> Report:
    """The reference: every part, every tilt, every other part, FCL for every decision (the
    placing surface a half-space in the part frame), no broadphase, no bounds, no caching;
    the gripper's frame built per tilt from its definition. Same results as
    `Validator.check` on the same geometry (`validator.geometry`), far slower."""
    start = time.perf_counter()
    v = geometry
    ids = [int(i) for i in ids]
    poses = check_poses(ids, poses)
    rows = target_rows(ids, targets)
    rotations = quaternions_to_matrices(poses[:, 3:])
    positions = poses[:, :3]
    walls = [fcl.CollisionObject(fcl.Box(*(2 * np.array(h))), fcl.Transform(np.eye(3),
                                                                          np.array(c)))
             for h, c in containers.wall_boxes(container)]
    surface = fcl.CollisionObject(fcl.Halfspace(-v.place_axis, -v.seat_offset),
                                  fcl.Transform())
    queries = 0
    results = []
    for row in rows:
        rotation, position = rotations[row], positions[row]
        centre = position + rotation @ v.part.center
        if not containers.inside(container, centre, CENTRE_TOLERANCE,
                                 v.config.rim_tolerance)[0]:
            results.append(PartResult(ids[row], STAGE_OUTSIDE, 'outside'))
            continue
        # each grasp as the gripper takes it: on a round body, turned about its axis by the
        # angle from the up axis to world +Z, both seen across the axis
        turns, turned = [], []
        for g, a in zip(v.grasps, v.free_axes, strict=True):
            w = rotation.T @ np.array([0.0, 0.0, 1.0])
            u_across, w_across = g.up - (g.up @ a) * a, w - (w @ a) * a
            turn = math.atan2(float(a @ np.cross(u_across, w_across)),
                              float(u_across @ w_across)) if a.any() else 0.0
            turns.append(turn)
            turned.append(rotation @ Rotation.from_rotvec(turn * a).as_matrix())
        angles = [math.acos(max(-1.0, min(1.0, float((r @ g.up)[2]))))
                  if v.usable[k] else math.pi      # a cup's grasp that cannot seal or hold
                  for k, (g, r) in enumerate(zip(v.grasps, turned, strict=True))]
        g = min((k for k in range(len(angles)) if angles[k] <= min(angles) + TIE),
                key=lambda k: (abs(turns[k]), k))
        grasp, gripped = v.grasps[g], turned[g]
        result = PartResult(ids[row], STAGE_CANDIDACY, '', g, angles[g],
                            jaw_opening=v.gripper.width(grasp))
        results.append(result)
        if angles[g] > v.config.tolerance:
            result.grasp_index = -1
            continue
        closing = gripped @ grasp.closing
        shapes = v.gripper.shapes(grasp, v.finger_depths[g])
        # the gripper's axis as its kind takes it (the jaws': the vertical made perpendicular
        # to the closing axis; the cup's: the grasp's up axis), turned by each tilt about x
        axis = v.gripper.approach(closing[None], gripped[None], grasp.up[None])[0]
        side = np.cross(axis, closing)
        frames = []
        for tilt in v.tilts:
            up = math.cos(tilt) * axis - math.sin(tilt) * side
            frames.append(np.column_stack([closing, np.cross(up, closing), up]))
        objects = [s.fcl_object() for s in shapes]
        approach = [k for k, f in enumerate(frames)
                    if f[2, 2] >= math.cos(v.config.approach_cone) - 1e-12]
        if not approach:
            continue
        kept = []
        for k in approach:
            relative = rotation.T @ frames[k]
            clear = True
            for s, obj in zip(shapes, objects, strict=True):
                obj.setTransform(fcl.Transform(relative @ s.rotation,
                                               grasp.point + relative @ s.center))
                queries += 1
                clear &= not collide(obj, surface)
            if clear:
                kept.append(k)
        if not kept and v.station_ok is not None:   # put down on the station, picked again
            for k in approach:
                relative = rotation.T @ frames[k]
                for p, ok in zip(v.placements, v.station_ok, strict=True):
                    station = fcl.CollisionObject(fcl.Halfspace(-p.normal, -p.offset),
                                                  fcl.Transform())
                    clear = ok
                    for s, obj in zip(shapes, objects, strict=True):
                        obj.setTransform(fcl.Transform(relative @ s.rotation,
                                                       grasp.point + relative @ s.center))
                        queries += 1
                        clear = clear and not collide(obj, station)
                    if clear:
                        kept.append(k)
                        result.regrasp = True
                        break
        if not kept:
            result.stage = STAGE_PLACEABILITY
            continue

        def placed(k, s, frames=frames, position=position, rotation=rotation, grasp=grasp):
            origin = position + rotation @ grasp.point
            return fcl.Transform(frames[k] @ s.rotation, origin + frames[k] @ s.center)

        free = []
        for k in kept:
            hit = False
            for s, obj in zip(shapes, objects, strict=True):
                obj.setTransform(placed(k, s))
                for wall in walls:
                    queries += 1
                    hit |= collide(obj, wall)
            if not hit:
                free.append(k)
        if not free:
            result.stage = STAGE_CONTAINER
            continue
        if neighbour_check:
            clear_tilts = []
            for k in free:
                hit = False
                for s, obj in zip(shapes, objects, strict=True):
                    obj.setTransform(placed(k, s))
                    for j in range(len(ids)):
                        if j == row:
                            continue
                        for shape in v.part_shapes:
                            other = shape.fcl_object()
                            other.setTransform(fcl.Transform(rotations[j] @ shape.rotation,
                                                             positions[j] + rotations[j]
                                                             @ shape.center))
                            queries += 1
                            hit |= collide(obj, other)
                if not hit:
                    clear_tilts.append(k)
            free = clear_tilts
            if not free:
                result.stage = STAGE_NEIGHBOUR
                continue
        result.stage = STAGE_VALID
        result.valid_tilts = tuple(float(v.tilts[k]) for k in free)
    return Report(results, neighbour_check, queries, time.perf_counter() - start)
