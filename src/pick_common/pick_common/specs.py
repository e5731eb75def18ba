"""What a caller asks of a world, shared by the world, the feeder controller and the experiment
file: the scene to build and a vibration of the tray, their limits and their checks.

Pure: no rclpy, no PyBullet. Units: metres, seconds, hertz.
"""

from dataclasses import dataclass, field
import math

from .containers import check_container, ContainerSpec
from .errors import check_vector, InvalidArgument, Limit
from .parts import PartSpec

MAX_INSTANCES = 64
MAX_PARTS_PER_INSTANCE = 5000
MAX_SEED = 2**63 - 1
MAX_PEAK_ACCELERATION = 200.0   # m/s^2 of tray motion, about 20 g
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


FIXED, RANDOM = 'fixed', 'random'
DIRECTIONS = (FIXED, RANDOM)


@dataclass(frozen=True)
class Vibration:
    """Tray motion x(t) = amplitude * sin(2 pi frequency t), per axis, for `duration` s.

    amplitude: peak displacement along the tray's x, y, z, m. frequency: Hz.
    direction: FIXED moves the tray along the amplitude as given; RANDOM turns its horizontal
    part (x, y) about the vertical by an angle drawn uniformly from the instance's generator,
    once per vibration, so that the pile spreads and tips with no net drift toward one wall.
    The default, a 3 mm vertical shake with a 3 mm horizontal one in a random direction
    (15.4 g peak), emptied the most feeder runs, in the fewest vibrations, of the profiles
    measured (world README, "Vibration"); a fixed in-phase x + z motion conveys the pile to one
    wall.
    """

    amplitude: tuple[float, float, float] = (0.003, 0.0, 0.003)
    frequency: float = 30.0
    duration: float = 0.5
    direction: str = RANDOM


def check_scene(scene: SceneSpec) -> SceneSpec:
    """Check the container and counts (the part is checked when its geometry is built)."""
    check_container(scene.container)
    LIMITS['instance_count'].check('instance_count', scene.instance_count)
    LIMITS['seed'].check('seed', scene.seed)
    return scene


def check_vibration(vib: Vibration) -> Vibration:
    """Check amplitude (each axis 0..20 mm, not all zero), frequency, the peak acceleration
    they give, duration and direction."""
    amplitude = check_vector('vibration.amplitude', vib.amplitude, 3, low=0.0, high=0.02)
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
