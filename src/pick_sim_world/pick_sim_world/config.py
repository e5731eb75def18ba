"""Frozen configuration of the world core, and its validation in one place.

The node builds these from its parameters and the services from their requests; both go
through `check_physics`, `check_scene` and `check_vibration`.
"""

from dataclasses import dataclass, field
import math

from .containers import check_container, ContainerSpec
from .errors import check_int, check_number, check_vector, InvalidArgument
from .parts import PartSpec

MAX_INSTANCES = 64
MAX_PARTS_PER_INSTANCE = 5000
MAX_SEED = 2**63 - 1
MAX_PEAK_ACCELERATION = 200.0   # m/s^2 of tray motion, about 20 g


@dataclass(frozen=True)
class PhysicsConfig:
    """Solver and settle settings.

    time_step: s. solver_iterations: per step. contact_breaking_threshold: m (Bullet's default
    0.02 m suits metre-sized bodies; for mm parts 0.001 m cuts the contact count).
    settle_*: a part rests when over the last `settle_window` s its position changed by at most
    `settle_linear_tolerance` m and its orientation by at most `settle_angular_tolerance` rad;
    the scene is settled when at most `settle_moving_fraction` of its parts (rounded down) do
    not rest: 0 waits for every part. Checked every `settle_check_period` s of simulated time.
    `max_settle_time`: the cap on simulated time, s, reported when hit.
    """

    time_step: float = 1.0 / 240.0
    solver_iterations: int = 30
    contact_breaking_threshold: float = 0.001
    settle_check_period: float = 0.05
    settle_window: float = 0.2
    settle_linear_tolerance: float = 0.0005
    settle_angular_tolerance: float = 0.035
    settle_moving_fraction: float = 0.02
    max_settle_time: float = 10.0


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


def check_physics(cfg: PhysicsConfig) -> PhysicsConfig:
    """Check every field; raise InvalidArgument naming the first that is wrong."""
    check_number('physics.time_step', cfg.time_step, low=1e-5, high=0.01)
    check_int('physics.solver_iterations', cfg.solver_iterations, low=1, high=500)
    check_number('physics.contact_breaking_threshold', cfg.contact_breaking_threshold,
                 low=1e-5, high=0.1)
    check_number('settle.check_period', cfg.settle_check_period, low=cfg.time_step, high=1.0)
    check_number('settle.window', cfg.settle_window, low=cfg.settle_check_period, high=10.0)
    check_number('settle.linear_tolerance', cfg.settle_linear_tolerance, low=0.0, high=0.1,
                 low_open=True)
    check_number('settle.angular_tolerance', cfg.settle_angular_tolerance, low=0.0, high=3.2,
                 low_open=True)
    check_number('settle.moving_fraction', cfg.settle_moving_fraction, low=0.0, high=0.5)
    check_number('settle.max_time', cfg.max_settle_time, low=cfg.settle_window, high=600.0)
    return cfg


def check_scene(scene: SceneSpec) -> SceneSpec:
    """Check the container and counts (the part is checked when its geometry is built)."""
    check_container(scene.container)
    check_int('instance_count', scene.instance_count, low=1, high=MAX_INSTANCES)
    check_int('seed', scene.seed, low=0, high=MAX_SEED)
    return scene


def check_vibration(vib: Vibration) -> Vibration:
    """Check amplitude (each axis 0..20 mm, not all zero), frequency, the peak acceleration
    they give, duration and direction."""
    amplitude = check_vector('vibration.amplitude', vib.amplitude, 3, low=0.0, high=0.02)
    if not any(amplitude):
        raise InvalidArgument('vibration.amplitude', amplitude, 'is zero on every axis')
    frequency = check_number('vibration.frequency', vib.frequency, low=0.1, high=500.0)
    peak = math.hypot(*amplitude) * (2.0 * math.pi * frequency) ** 2
    if peak > MAX_PEAK_ACCELERATION:
        raise InvalidArgument('vibration.amplitude', amplitude,
                              f'at {frequency:g} Hz gives a peak acceleration of '
                              f'{peak:.4g} m/s^2 (limit {MAX_PEAK_ACCELERATION:g})')
    check_number('vibration.duration', vib.duration, low=0.0, high=60.0, low_open=True)
    if vib.direction not in DIRECTIONS:
        raise InvalidArgument('vibration.direction', vib.direction,
                              f'must be one of {", ".join(DIRECTIONS)}')
    return vib
