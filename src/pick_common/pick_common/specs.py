"""What a caller asks of a world, shared by the world, the feeder controller and the experiment
file: the scene to build and a vibration of the tray, their limits and their checks.

Pure: no rclpy, no PyBullet. Units: metres, seconds, hertz.
"""

from dataclasses import dataclass, field
import math

from .containers import check_container, ContainerSpec
from .errors import check_number, InvalidArgument, Limit
from .parts.spec import PartSpec

MAX_INSTANCES = 64
MAX_PARTS_PER_INSTANCE = 5000
MAX_SEED = 2**63 - 1
MAX_PEAK_ACCELERATION = 200.0   # m/s^2 of tray motion, about 20 g
MAX_MOVES = 16                  # moves in one feeder cycle
LIMITS = {
    'instance_count': Limit(1, MAX_INSTANCES, integer=True),
    'seed': Limit(0, MAX_SEED, integer=True),
    'vibration.frequency': Limit(0.1, 500.0),                     # Hz
    'vibration.duration': Limit(0.0, 60.0, low_open=True),        # s
}


@dataclass(frozen=True)
class SceneSpec:
    """What to build: one container and part model, repeated in `instance_count` instances.

    seed: base seed; instance k draws from a generator seeded with (seed, k).
    """

    container: ContainerSpec = field(default_factory=ContainerSpec)
    part: PartSpec = field(default_factory=PartSpec)
    instance_count: int = 1
    seed: int = 0


FIXED, RANDOM, CENTRE = 'fixed', 'random', 'centre'
DIRECTIONS = (FIXED, RANDOM, CENTRE)


@dataclass(frozen=True)
class Vibration:
    """Tray motion x(t) = amplitude * sin(2 pi frequency t), per axis, for `duration` s.

    amplitude: peak displacement along the tray's x, y, z, m. frequency: Hz.
    direction: FIXED moves the tray along the amplitude as given; RANDOM turns its horizontal
    part (x, y) about the vertical by an angle drawn uniformly from the instance's generator,
    once per vibration, so that the pile spreads with no net drift toward one wall; CENTRE
    lays its horizontal length along the line from the parts' centroid on the tray to the
    tray's centre, as a flexible feeder's centring vibration does (the Asycube's takes the
    parts' centre of mass from the camera: programming guide, table 5-3), so that the parts
    gather away from the walls, and for the share of `duration` the centroid's farthest
    normalised coordinate gives (0 at the centre, 1 at a wall: the Asycube's smart centering
    sets its duration so; world.vibrate), so `duration` is the centring from a wall; with no
    part, or the centroid at the centre, the tray does not move.
    The default is a flip (vertical only) at the vertical speed of a real feeder's: 1.4 mm at
    26 Hz is a peak vertical speed of 0.23 m/s (3.8 g), the SHOP4CF shakeit feeder's flip
    (26 Hz, at most 0.23 m/s). The named move `spread` adds an equal horizontal stroke in phase,
    in a random direction, which throws the pile along a 45 degree line as a linear vibratory
    conveyor does (world README, "Vibration").
    """

    amplitude: tuple[float, float, float] = (0.0, 0.0, 0.0014)
    frequency: float = 26.0
    duration: float = 0.5
    direction: str = FIXED


# The feeder moves a cell can sequence, modelled on a flexible feeder's vibration types (the
# Asycube's forward A, backward F, left D, right E, flip I and centering; world README,
# "Feeder moves"): each at the default's stroke and frequency. 'flip' is the default Vibration.
_STROKE, _HZ, _S = 0.0014, 26.0, 0.5
MOVES = {
    'flip': Vibration(),                                            # vertical: turns parts over
    'centre': Vibration((_STROKE, 0.0, _STROKE), _HZ, _S, CENTRE),  # toward the tray's centre
    'forward': Vibration((_STROKE, 0.0, _STROKE), _HZ, _S, FIXED),  # conveys toward +x
    'backward': Vibration((-_STROKE, 0.0, _STROKE), _HZ, _S, FIXED),
    'left': Vibration((0.0, _STROKE, _STROKE), _HZ, _S, FIXED),     # toward +y
    'right': Vibration((0.0, -_STROKE, _STROKE), _HZ, _S, FIXED),
    'spread': Vibration((_STROKE, 0.0, _STROKE), _HZ, _S, RANDOM),  # a throw, random direction:
}                                                                   # no feeder documents it
# The default vibration cycle of a feeder: the Asycube's typical vibration sequence after a
# feed, "a centering action" then "flip: flip and spread the parts" (Asyril, EYE+ Studio
# recipe wizard, "Vibration Sequence"); the wait after it is the world's settle
# (docs/physics.md, "Feeder moves").
DEFAULT_CYCLE = ('centre', 'flip')


def check_scene(scene: SceneSpec) -> SceneSpec:
    """Check the container and counts (the part is checked when its geometry is built)."""
    check_container(scene.container)
    LIMITS['instance_count'].check('instance_count', scene.instance_count)
    LIMITS['seed'].check('seed', scene.seed)
    return scene


def check_vibration(vib: Vibration) -> Vibration:
    """Check amplitude (x and y within +-20 mm, z 0..20 mm, not all zero), frequency, the
    peak acceleration they give, duration and direction."""
    values = tuple(vib.amplitude)
    if len(values) != 3:
        raise InvalidArgument('vibration.amplitude', values, 'must have 3 elements')
    amplitude = tuple(check_number(f'vibration.amplitude[{i}]', v, low=-0.02 if i < 2 else 0.0,
                                   high=0.02) for i, v in enumerate(values))
    if not any(amplitude):
        raise InvalidArgument('vibration.amplitude', amplitude, 'is zero on every axis')
    frequency = LIMITS['vibration.frequency'].check('vibration.frequency', vib.frequency)
    peak = math.hypot(*amplitude) * (2.0 * math.pi * frequency) ** 2
    if peak > MAX_PEAK_ACCELERATION:
        raise InvalidArgument('vibration.amplitude', amplitude,
                              f'at {frequency:g} Hz gives a peak acceleration of '
                              f'{peak:.4g} m/s^2 (limit {MAX_PEAK_ACCELERATION:g})')
    LIMITS['vibration.duration'].check('vibration.duration', vib.duration)
    if vib.direction not in DIRECTIONS:
        raise InvalidArgument('vibration.direction', vib.direction,
                              f'must be one of {", ".join(DIRECTIONS)}')
    return vib
