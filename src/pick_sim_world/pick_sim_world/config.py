"""Frozen physics configuration of the world core, its limits and its check, in one place.

The node declares its parameters from LIMITS (pick_common.node_runner.declare) and builds a
PhysicsConfig; `check_physics` enforces the same LIMITS and the rules between fields. The scene
and vibration specs every package shares are pick_common.specs.
"""

from dataclasses import dataclass

from pick_common import containers
from pick_common.errors import InvalidArgument, Limit
from pick_common.parts.insets import ENGINE_UNIT

GRAVITY = 9.81                  # m/s^2, standard gravity

# The range of every physics and settle setting, by parameter name.
LIMITS = {
    'physics.time_step': Limit(1e-5, 0.01),
    'physics.solver_iterations': Limit(1, 500, integer=True),
    'physics.tray_solver_iterations': Limit(1, 500, integer=True),
    'physics.warm_starting_factor': Limit(0.0, 1.0),
    'physics.contact_breaking_threshold': Limit(1e-5, 0.1),
    'physics.length_unit': Limit(1e-3, 1.0),
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

    time_step: s. 1/480: at pybullet's 1/240, 480 TO-220s dropped into a 300 x 300 x 26 mm bin
    lean steeper (2.6 % of them tilted past every grasp's tolerance against 1.3 to 1.7 % at
    1/480, 1/960 and 1/1920), and the bin's container-free fraction lies 2 points below the
    finer steps' (0.908 against 0.926 / 0.930 / 0.927, 12 seeds; studies/lean.py); on a tray at
    1/240 s feeder runs need a quarter more vibrations than at 1/960 s (docs/physics.md, "The
    tray at 1/240 s"). solver_iterations: per step, in a bin.
    tray_solver_iterations: per step, on a tray. 100 keep a bin's deep pile at rest: with 50,
    150 TO-220s settled in a 75 x 75 x 60 mm bin crept (5 seeds: 170 moves > 0.5 mm over three
    further seconds against 24 at 100; studies/creep.py). Parts on a tray lie about one deep, and
    there 50 leave them as still as 100 (90 parts on 195 x 150 mm, 4 seeds of PTH0's and PTH1's
    parts: 3 moves against 5) for two thirds of the time per step, with every answer of the
    tray inside the finest settings' intervals (docs/physics.md, "Iterations on the tray").
    warm_starting_factor: the share of each contact's impulse of the last step the solver starts
    from. 0.85 is Bullet's own default (btContactSolverInfo); pybullet sets 0.1, at which a
    pile's contacts are re-solved from a tenth each step and piles creep (studies/creep.py); at 1
    the solver throws parts: a TO-220 lying still gained 3.6 m/s and 494 rad/s in one step,
    which the same state solved from a warm start of 0 did not; studies/throws.py counts the parts
    thrown and off the tray per setting (600 moves: 5 off the tray at 1, none at 0.85).
    contact_breaking_threshold: how near two shapes keep a contact, as a factor of each shape's
    bounding radius (Bullet's relative threshold, engine.py: at 0.001 a 10 mm cube reports the
    floor within 0.009 mm of its surface, in metres and in centimetres alike). 0.02, Bullet's
    own (gContactBreakingThreshold): in centimetres at 0.001 and 0.002 a lying 6 mm cylinder
    kept one contact point and sank 0.36 mm into the floor, creeping at 0.8 to 3.9 mm/s, where
    at 0.005 to 0.02 it kept two and rested 0.2 to 0.4 um deep (0.001 served in metres, where
    every hull's 1 mm margin held its contacts).
    length_unit: m per length unit of the engine: 0.01, centimetres, where parts of 0.5 to 100
    mm measure Bullet's 0.05 to 10 units and pybullet's fixed hull margin is 0.01 mm (in
    metres, 1 mm: a fifth of a 5 mm part; engine.py). 1 simulates in metres, for comparisons.
    settle_*: a part rests when over the last `settle_window` s its position changed by at most
    `settle_linear_tolerance` m and its orientation by at most `settle_angular_tolerance` rad;
    the scene is settled when at most `settle_moving_fraction` of its parts (rounded down) do
    not rest: 0 waits for every part. Checked every `settle_check_period` s of simulated time.
    `max_settle_time`: the cap on simulated time, s, reported when hit.
    settle_freeze: while parts fall and settle, freeze the parts that rest (static until a
    moving part comes near; freezing.py): 1.25 to 3.3 times faster, with the answers inside the
    intervals of stepping every part (docs/physics.md, "Freezing what rests"). False steps
    every part to the end.
    """

    time_step: float = 1.0 / 480.0
    solver_iterations: int = 100
    tray_solver_iterations: int = 50
    warm_starting_factor: float = 0.85
    contact_breaking_threshold: float = 0.02
    length_unit: float = ENGINE_UNIT
    settle_check_period: float = 0.05
    settle_window: float = 0.2
    settle_linear_tolerance: float = 0.0005
    settle_angular_tolerance: float = 0.035
    settle_moving_fraction: float = 0.02
    max_settle_time: float = 10.0
    settle_freeze: bool = True


def solver_iterations(cfg: PhysicsConfig, kind: str) -> int:
    """The solver iterations per step for a container of `kind` (containers.BIN or TRAY)."""
    return cfg.tray_solver_iterations if kind == containers.TRAY else cfg.solver_iterations


def check_physics(cfg: PhysicsConfig) -> PhysicsConfig:
    """Check every field; raise InvalidArgument naming the first that is wrong."""
    def check(name: str, value, low: float | None = None):
        return LIMITS[name].check(name, value, low=low)

    check('physics.time_step', cfg.time_step)
    check('physics.solver_iterations', cfg.solver_iterations)
    check('physics.tray_solver_iterations', cfg.tray_solver_iterations)
    check('physics.warm_starting_factor', cfg.warm_starting_factor)
    check('physics.contact_breaking_threshold', cfg.contact_breaking_threshold)
    check('physics.length_unit', cfg.length_unit)
    check('settle.check_period', cfg.settle_check_period, cfg.time_step)
    check('settle.window', cfg.settle_window, cfg.settle_check_period)
    check('settle.linear_tolerance', cfg.settle_linear_tolerance)
    check('settle.angular_tolerance', cfg.settle_angular_tolerance)
    check('settle.moving_fraction', cfg.settle_moving_fraction)
    check('settle.max_time', cfg.max_settle_time, cfg.settle_window)
    if not isinstance(cfg.settle_freeze, bool):
        raise InvalidArgument('settle.freeze', cfg.settle_freeze, 'must be true or false')
    return cfg
