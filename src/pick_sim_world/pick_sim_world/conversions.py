"""The world's own message conversions: its scene description and its markers. The shared
types (containers, part specs, snapshots, settle reports, vibrations, error codes) are mapped
in pick_common.conversions.

No rclpy here: messages are plain Python classes. Times are passed in as builtin Time messages.
"""

import copy

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Quaternion, Transform, TransformStamped, Vector3
import numpy as np
from pick_common import containers
from pick_common.conversions import contact_to_msg, container_to_msg, instance_frame, pose_msg
from pick_common.parts.geometry import PartGeometry
from pick_common.parts.primitives import Box, Cylinder
from pick_common.states import PartStates
from pick_msgs.msg import Instance as InstanceMsg
from pick_msgs.msg import PartModel, Scene
from shape_msgs.msg import Mesh, MeshTriangle, SolidPrimitive
from std_msgs.msg import ColorRGBA, Header
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from .world import World


def _mesh_msg(vertices: np.ndarray, faces: np.ndarray) -> Mesh:
    return Mesh(vertices=[Point(x=float(x), y=float(y), z=float(z)) for x, y, z in vertices],
                triangles=[MeshTriangle(vertex_indices=[int(a), int(b), int(c)])
                           for a, b, c in faces])


def part_model_to_msg(part: PartGeometry) -> PartModel:
    """The full part model: parameters, collision compound and visual mesh."""
    spec = part.spec
    msg = PartModel(
        name=spec.model, mesh_path=spec.mesh_path, scale=float(spec.scale),
        dimension_names=list(part.dimensions), dimension_values=[
            float(v) for v in part.dimensions.values()],
        mass=float(part.mass), part_on_surface=contact_to_msg(spec.part_on_surface),
        part_on_part=contact_to_msg(spec.part_on_part),
        bounding_radius=float(part.radius + np.linalg.norm(part.center)))
    for p in part.primitives:
        if isinstance(p, Box):
            msg.primitives.append(SolidPrimitive(
                type=SolidPrimitive.BOX, dimensions=[2.0 * s for s in p.half]))
            msg.primitive_poses.append(pose_msg(p.position, p.orientation))
        elif isinstance(p, Cylinder):
            msg.primitives.append(SolidPrimitive(type=SolidPrimitive.CYLINDER,
                                                 dimensions=[p.length, p.radius]))
            msg.primitive_poses.append(pose_msg(p.position, p.orientation))
        else:
            msg.hulls.append(_mesh_msg(p.vertices, p.faces))
    msg.visual = _mesh_msg(part.visual.vertices, part.visual.faces)
    return msg


# ----------------------------------------------------------------------------- scene
def scene_to_msg(world: World, stamp: Time, frame_id: str, prefix: str) -> Scene:
    """The scene description of a world: part model and every instance with its frame."""
    msg = Scene(header=Header(stamp=stamp, frame_id=frame_id),
                part_model=part_model_to_msg(world.part))
    container = container_to_msg(world.scene.container)
    for inst in world.instances:
        x, y, z = (float(v) for v in inst.origin)
        msg.instances.append(InstanceMsg(
            id=inst.id, seed=inst.seed, frame_id=instance_frame(prefix, inst.id),
            transform=Transform(translation=Vector3(x=x, y=y, z=z),
                                rotation=Quaternion(w=1.0)),
            container=container, part_count=len(inst.part_ids)))
    return msg


def tf_static_msg(scene: Scene) -> TFMessage:
    """The transforms of a scene's instance frames from its frame (the world), for
    /tf_static: so that RViz or Foxglove put a worker's markers (in instance frames) and parts
    in one frame."""
    return TFMessage(transforms=[
        TransformStamped(header=scene.header, child_frame_id=inst.frame_id,
                         transform=inst.transform) for inst in scene.instances])


# ----------------------------------------------------------------------------- markers
_CONTAINER_COLOR = ColorRGBA(r=0.6, g=0.6, b=0.65, a=0.4)
_PART_COLOR = ColorRGBA(r=0.1, g=0.3, b=0.8, a=1.0)
_ESCAPED_COLOR = ColorRGBA(r=0.9, g=0.1, b=0.1, a=1.0)


# The last part's marker shapes (`_shapes`): (its primitives, their shapes).
_shapes_of: tuple[tuple, list] = ((), [])


def _shapes(primitives: tuple) -> list:
    """Per primitive: marker type, scale and points, shared by every part's marker and by
    every call for the same primitives (a world node's part): a CAD part's hulls hold
    thousands of points (KiCad's DIP-28 socket 11,604), which built anew after each operation
    took more of a feeder run's world than its physics."""
    global _shapes_of
    cached, shapes = _shapes_of
    if cached is primitives:
        return shapes
    shapes = []
    for p in primitives:
        if isinstance(p, Box):
            shapes.append((Marker.CUBE, Vector3(x=2 * p.half[0], y=2 * p.half[1],
                                                z=2 * p.half[2]), []))
        elif isinstance(p, Cylinder):
            shapes.append((Marker.CYLINDER, Vector3(x=2 * p.radius, y=2 * p.radius,
                                                    z=p.length), []))
        else:
            shapes.append((Marker.TRIANGLE_LIST, Vector3(x=1.0, y=1.0, z=1.0),
                           [Point(x=float(x), y=float(y), z=float(z))
                            for x, y, z in p.vertices[p.faces.reshape(-1)]]))
    _shapes_of = (primitives, shapes)
    return shapes


def part_frame(prefix: str, part_id: int) -> str:
    """Name of part `part_id`'s frame: its pose from its instance frame on /tf
    (`parts_tf_msg`), its markers drawn in it."""
    return f'{prefix}part_{part_id}'


def parts_tf_msg(states: PartStates, stamp: Time, prefix: str) -> TFMessage:
    """Each part's frame (`part_frame`) from its instance frame, for /tf: what moves the
    parts' frame-locked markers after each operation (a few hundred bytes a part, where
    markers of their hulls' points are megabytes)."""
    headers: dict[int, Header] = {}
    out = TFMessage()
    for pid, inst, pose in zip(states.ids.tolist(), states.instances.tolist(),
                               states.poses.tolist(), strict=True):
        header = headers.get(inst)
        if header is None:
            header = headers[inst] = Header(stamp=stamp, frame_id=instance_frame(prefix, inst))
        out.transforms.append(TransformStamped(
            header=header, child_frame_id=part_frame(prefix, pid), transform=Transform(
                translation=Vector3(x=pose[0], y=pose[1], z=pose[2]),
                rotation=Quaternion(x=pose[3], y=pose[4], z=pose[5], w=pose[6]))))
    return out


def drawn(states: PartStates) -> tuple[bytes, bytes]:
    """What the parts' markers show (`markers_msg`): which parts there are and which are
    inside their container. Markers need publishing again only when it changes."""
    return states.ids.tobytes(), states.inside.tobytes()


def markers_msg(world: World, states: PartStates, stamp: Time, prefix: str) -> MarkerArray:
    """Containers in their instance frames and parts in their own frames (`part_frame`,
    frame-locked: a viewer moves them with the part's frame on /tf, `parts_tf_msg`): one
    marker per collision primitive (CUBE, CYLINDER) or hull (TRIANGLE_LIST) at its pose in
    the part. Starts with DELETEALL. Publish it again when `drawn` changes.

    A part's markers are copies of one per colour and primitive that share its scale,
    colour, pose and hull points."""
    out = MarkerArray(markers=[Marker(action=Marker.DELETEALL)])
    marker_id = 0
    for inst in world.instances:
        header = Header(stamp=stamp, frame_id=instance_frame(prefix, inst.id))
        for half, center in containers.wall_boxes(world.scene.container):
            out.markers.append(Marker(
                header=header, ns='container', id=marker_id, type=Marker.CUBE,
                pose=pose_msg(center, (0.0, 0.0, 0.0, 1.0)),
                scale=Vector3(x=2 * half[0], y=2 * half[1], z=2 * half[2]),
                color=_CONTAINER_COLOR))
            marker_id += 1
    if not len(states.ids):
        return out
    primitives = world.part.primitives
    shapes = _shapes(primitives)
    # Per colour and primitive, one marker to copy: a copy shares the fields every part's
    # marker has in common and skips the type checks a Marker built from keywords makes on
    # each (building 1.8 to 2.2 times faster: bench/graph/bench_conversions.py).
    templates = {(inside, k): Marker(
        id=k, type=kind, scale=scale, points=points, frame_locked=True,
        pose=pose_msg(p.position, p.orientation),
        color=_PART_COLOR if inside else _ESCAPED_COLOR)
        for inside in (True, False) for k, (p, (kind, scale, points))
        in enumerate(zip(primitives, shapes, strict=True))}
    for pid, inside in zip(states.ids.tolist(), states.inside.tolist(), strict=True):
        header = Header(stamp=stamp, frame_id=part_frame(prefix, pid))
        ns = part_frame('', pid)            # the namespace: the frame's name, unprefixed
        for k in range(len(primitives)):
            marker = copy.copy(templates[inside, k])
            marker.header = header
            marker.ns = ns
            out.markers.append(marker)
    return out
