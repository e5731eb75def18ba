"""Contact materials as pairs: what a part does against the container's surface (a bin's or a
tray's floor and walls) and against another part, and the one coefficient per body that makes
the physics apply exactly each pair's value.

A friction coefficient, a restitution or a rolling resistance belongs to a pair of surfaces,
not to one body. Bullet keeps one value per body and combines two bodies' values at every
contact (btManifoldResult's calculateCombined*):
- lateral friction and restitution: the product, friction_a * friction_b, e_a * e_b;
- rolling and spinning arms: arm_a * friction_b + arm_b * friction_a;
each combined friction capped at MAX_COMBINED (10). With only part and surface bodies in a
scene, the part's values fix the part-on-part pair (friction_p = sqrt(mu_pp), arm_p =
arm_pp / (2 friction_p)) and the surface's then fix the part-on-surface pair; a pair value of
0 keeps the other pair's product by a part value of TINY, whose own square is 0 to 1e-12. A
part-on-surface arm below arm_pp * mu_ps / (2 mu_pp) would need a negative arm on the surface,
which Bullet's solver ignores: refused, naming both pairs.

Pure: no simulator. Lengths in metres.
"""

from dataclasses import dataclass, replace
import math

from ..errors import InvalidArgument, Limit

MAX_COMBINED = 10.0       # Bullet's cap on a combined friction, lateral, rolling or spinning
TINY = 1e-6               # a body's coefficient that stands for a pair value of 0

# Where the defaults come from: friction from The Engineering ToolBox, "Friction and Friction
# Coefficients for some Common Materials" (polystyrene on steel, clean and dry, 0.3 to 0.35:
# an epoxy or plastic package on a steel tray plate; polystyrene on polystyrene, 0.5: package
# on package); the part on a bin's plastic walls is taken as on the plate. Restitution and the
# rolling and spinning arms: assumed, no published table for small packages found (a drop test
# calibrates them: docs/drop-tests.md).
SOURCE = ('friction: The Engineering ToolBox, Friction and Friction Coefficients for some '
          'Common Materials (polystyrene on steel 0.3-0.35, polystyrene on polystyrene 0.5); '
          'restitution, rolling and spinning arms: assumed')

# How a value was got, as a file's `basis` and the report say it: measured on the user's own
# parts, calibrated to a drop test's counts, published (a cited table), or assumed. The
# defaults' bases, by field: friction from the table above, the rest assumed.
BASES = ('measured', 'calibrated', 'published', 'assumed')
DEFAULT_BASIS = {'lateral_friction': 'published', 'rolling_friction': 'assumed',
                 'spinning_friction': 'assumed', 'restitution': 'assumed'}


@dataclass(frozen=True)
class Contact:
    """What happens where two surfaces touch. lateral_friction: Coulomb coefficient;
    rolling_friction and spinning_friction: resistance arms, m (torque = arm * normal force);
    restitution: normal rebound speed over approach speed."""

    lateral_friction: float
    rolling_friction: float
    spinning_friction: float
    restitution: float


PART_ON_SURFACE = Contact(lateral_friction=0.35, rolling_friction=1e-4,
                          spinning_friction=1e-4, restitution=0.3)
PART_ON_PART = Contact(lateral_friction=0.5, rolling_friction=1e-4,
                       spinning_friction=1e-4, restitution=0.3)

# The range of each pair value, by the file's field name (m for the arms).
LIMITS = {
    'lateral_friction': Limit(0.0, MAX_COMBINED),
    'rolling_friction': Limit(0.0, 0.1),
    'spinning_friction': Limit(0.0, 0.1),
    'restitution': Limit(0.0, 1.0),
}
FIELDS = tuple(LIMITS)


@dataclass(frozen=True)
class BodyValues:
    """One body's coefficients as Bullet takes them (changeDynamics)."""

    lateral_friction: float
    rolling_friction: float
    spinning_friction: float
    restitution: float


def combined(a: BodyValues, b: BodyValues) -> Contact:
    """The pair values Bullet applies where bodies of `a` and `b` touch."""
    def cap(x: float) -> float:
        return max(-MAX_COMBINED, min(MAX_COMBINED, x))
    fa, fb = a.lateral_friction, b.lateral_friction
    return Contact(cap(fa * fb), cap(a.rolling_friction * fb + b.rolling_friction * fa),
                   cap(a.spinning_friction * fb + b.spinning_friction * fa),
                   a.restitution * b.restitution)


def check_contact(contact: Contact, where: str) -> Contact:
    """The pair's values within LIMITS, each named `where`.<field>."""
    for name in FIELDS:
        LIMITS[name].check(f'{where}.{name}', getattr(contact, name))
    return contact


def body_values(on_surface: Contact, on_part: Contact, where: str = 'materials'
                ) -> tuple[BodyValues, BodyValues]:
    """The part's and the surface's coefficients whose combinations are `on_surface` (part
    against surface) and `on_part` (part against part) (module docstring); InvalidArgument
    named `where`.part_on_surface.<field> when Bullet cannot apply a pair."""
    check_contact(on_surface, f'{where}.part_on_surface')
    check_contact(on_part, f'{where}.part_on_part')
    f_part = max(math.sqrt(on_part.lateral_friction), TINY)
    e_part = max(math.sqrt(on_part.restitution), TINY)
    f_surface = on_surface.lateral_friction / f_part
    arms_part, arms_surface = [], []
    for name in ('rolling_friction', 'spinning_friction'):
        pp, ps = getattr(on_part, name), getattr(on_surface, name)
        arm_part = pp / (2.0 * f_part)
        floor = arm_part * f_surface      # what the part's arm alone gives against a surface
        if ps < floor * (1.0 - 1e-9):
            raise InvalidArgument(
                f'{where}.part_on_surface.{name}', ps,
                f'must be at least {floor:.6g} m beside part_on_part ({name} {pp:g} m, '
                f"lateral_friction {on_part.lateral_friction:g}) and part_on_surface's "
                f'lateral_friction {on_surface.lateral_friction:g}: Bullet combines arms as '
                'arm_a * friction_b + arm_b * friction_a and cannot apply a lower one')
        arms_part.append(arm_part)
        arms_surface.append(max(ps - floor, 0.0) / f_part)
    part = BodyValues(f_part, arms_part[0], arms_part[1], e_part)
    surface = BodyValues(f_surface, arms_surface[0], arms_surface[1],
                         on_surface.restitution / e_part)
    return part, surface


def arms(arm: float, on_surface: Contact = PART_ON_SURFACE, on_part: Contact = PART_ON_PART
         ) -> dict[str, Contact]:
    """Both pairs with rolling and spinning arms `arm` (m), as PartSpec's keywords."""
    return {'part_on_surface': replace(on_surface, rolling_friction=arm, spinning_friction=arm),
            'part_on_part': replace(on_part, rolling_friction=arm, spinning_friction=arm)}
