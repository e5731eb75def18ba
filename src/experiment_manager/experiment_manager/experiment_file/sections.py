"""The file's sections as the SI dataclasses a run uses: the gripper and the check (mm and degrees
to m and rad), the requirements (hours to s), the tray and the table's moves (mm to m, each
move's unset keys from the named move of pick_common.specs.MOVES), each checked by its core's
rule under the file's key names."""

from dataclasses import replace

from pick_common.containers import check_container, ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import PartGeometry
from pick_common.specs import check_vibration, MOVES, Vibration
from pick_validity.config import CheckConfig
from pick_validity.grippers import GripperKind, KINDS

from . import schema
from .errors import checked as checked_as
from .model import DEG, MM, Requirements


def gripper(g: schema.GripperSection) -> GripperKind:
    """The section's gripper, of the kind its type names, in SI units; a key left out, its
    kind's default."""
    kind = KINDS[g.type]
    return kind(**{key.field: key.factor * getattr(g, key.file_key) for key in kind.KEYS
                   if getattr(g, key.file_key) is not None})


def check(c: schema.CheckSection) -> CheckConfig:
    return CheckConfig(tolerance=DEG * c.tolerance_deg, tilt_min=DEG * c.tilt_min_deg,
                       tilt_max=DEG * c.tilt_max_deg, tilt_step=DEG * c.tilt_step_deg,
                       approach_cone=DEG * c.approach_cone_deg,
                       rim_tolerance=MM * c.rim_tolerance_mm, station_margin=c.station_margin)


def requirements(r: schema.RequirementsSection) -> Requirements:
    return Requirements(parts_per_hour=r.parts_per_hour,
                        refill_interval=3600.0 * r.refill_interval_h,
                        max_dimension=MM * r.max_dimension_mm,
                        max_spilled=r.max_spilled_parts, success_rate=r.success_rate)


def tray(top: schema.FileKeys) -> ContainerSpec:
    tray = replace(ContainerSpec.tray(tuple(MM * s for s in top.tray_mm)),
                   drop_height=MM * top.hopper_lip_mm, hopper_rate=top.hopper_rate,
                   hopper_speed=MM * top.hopper_speed_mm_s)
    checked_as(check_container, tray, 'tray_mm')
    zone = top.feeder_zone_mm
    if zone is not None:
        (cx, cy), (sx, sy), (x, y, _) = zone.center, zone.size, top.tray_mm
        if abs(cx) + sx / 2 > x / 2 + 1e-9 or abs(cy) + sy / 2 > y / 2 + 1e-9:
            raise InvalidArgument('feeder_zone_mm', {'center': [cx, cy], 'size': [sx, sy]},
                                  f"reaches from {cx - sx / 2:g} to {cx + sx / 2:g} mm along "
                                  f"x and {cy - sy / 2:g} to {cy + sy / 2:g} mm along y: it "
                                  f"must lie on the tray's plate, within +-{x / 2:g} and "
                                  f'+-{y / 2:g} mm of its centre (tray_mm)')
        tray = replace(tray, feeder_zone_center=(MM * cx, MM * cy),
                       feeder_zone_size=(MM * sx, MM * sy))
    return tray


def zone_holds(size: tuple[float, float], geometry: PartGeometry) -> None:
    """The feeder zone (mm) is wider than the part in any orientation (its enclosing sphere),
    so that the world can drop parts into it."""
    across = 2.0 * geometry.radius / MM
    if min(size) < across:
        raise InvalidArgument('feeder_zone_mm.size', list(size), f'is smaller than the part '
                              f'({across:.1f} mm across in some orientation): parts cannot be '
                              'dropped into it')


def moves(top: schema.FileKeys) -> tuple[Vibration, ...]:
    out = []
    for i, m in enumerate(top.moves):
        base = MOVES[m.move]
        move = Vibration(
            amplitude=tuple(MM * a for a in m.amplitude_mm) if m.amplitude_mm is not None
            else tuple(MM * float(a / MM) for a in base.amplitude),
            frequency=m.frequency_hz if m.frequency_hz is not None else float(base.frequency),
            duration=m.duration_s if m.duration_s is not None else float(base.duration),
            direction=m.direction if m.direction is not None else base.direction)
        out.append(checked_as(check_vibration, move, f'moves[{i}]'))
    return tuple(out)
