"""Frozen physics configuration of the world core, its limits and its check, in one place.

The node declares its parameters from LIMITS (pick_common.node_runner.declare) and builds a
PhysicsConfig; `check_physics` enforces the same LIMITS and the rules between fields. The scene
and vibration specs every package shares are pick_common.specs.
"""

from dataclasses import dataclass

from pick_common.errors import Limit

GRAVITY = 9.81                  # m/s^2, standard gravity

# The range of every physics and settle setting, by parameter name.
LIMITS = {
    'physics.time_step': Limit(1e-5, 0.01),
    'physics.solver_iterations': Limit(1, 500, integer=True),
    'physics.warm_starting_factor': Limit(0.0, 1.0),
    'physics.contact_breaking_threshold': Limit(1e-5, 0.1),
    'settle.check_period': Limit(1e-5, 1.0),         # and at least physics.time_step
    'settle.window': Limit(1e-5, 10.0),              # and at least settle.check_period
    'settle.linear_tolerance': Limit(0.0, 0.1, low_open=True),
    'settle.angular_tolerance': Limit(0.0, 3.2, low_open=True),
    'settle.moving_fraction': Limit(0.0, 0.5),
    'settle.max_time': Limit(1e-3, 600.0),           # and at least settle.window
}


@dataclass(frozen=True)
class PhysicsConfig:
    """Solver and settle settings.

    time_step: s. solver_iterations: per step. warm_starting_factor: the share of each
    contact's impulse of the last step the solver starts from (pybullet sets 0.1, Bullet's
    own default is 0.85; at 1 a pile's contact forces carry over from step to step instead
    of being re-solved from a tenth each step: the piles of bench_creep.py settle sooner,
    with less overlap).
    contact_breaking_threshold: m (Bullet's default 0.02 m suits metre-sized bodies; for mm
    parts 0.001 m cuts the contact count).
    settle_*: a part rests when over the last `settle_window` s its position changed by at most
    `settle_linear_tolerance` m and its orientation by at most `settle_angular_tolerance` rad;
    the scene is settled when at most `settle_moving_fraction` of its parts (rounded down) do
    not rest: 0 waits for every part. Checked every `settle_check_period` s of simulated time.
    `max_settle_time`: the cap on simulated time, s, reported when hit.
    """

    time_step: float = 1.0 / 240.0
    solver_iterations: int = 100
    warm_starting_factor: float = 1.0
    contact_breaking_threshold: float = 0.001
    settle_check_period: float = 0.05
    settle_window: float = 0.2
    settle_linear_tolerance: float = 0.0005
    settle_angular_tolerance: float = 0.035
    settle_moving_fraction: float = 0.02
    max_settle_time: float = 10.0


def check_physics(cfg: PhysicsConfig) -> PhysicsConfig:
    """Check every field; raise InvalidArgument naming the first that is wrong."""
    def check(name: str, value, low: float | None = None):
        return LIMITS[name].check(name, value, low=low)

    check('physics.time_step', cfg.time_step)
    check('physics.solver_iterations', cfg.solver_iterations)
    check('physics.warm_starting_factor', cfg.warm_starting_factor)
    check('physics.contact_breaking_threshold', cfg.contact_breaking_threshold)
    check('settle.check_period', cfg.settle_check_period, cfg.time_step)
    check('settle.window', cfg.settle_window, cfg.settle_check_period)
    check('settle.linear_tolerance', cfg.settle_linear_tolerance)
    check('settle.angular_tolerance', cfg.settle_angular_tolerance)
    check('settle.moving_fraction', cfg.settle_moving_fraction)
    check('settle.max_time', cfg.max_settle_time, cfg.settle_window)
    return cfg
