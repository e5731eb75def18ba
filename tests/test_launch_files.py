"""The launch files. ros2/launch is not on PyPI (ROS_WHEELS.md), so they cannot run
here; what can be checked without it is: every node of the graph has a launch file that starts
it, a worker node's launch file defaults to the parameter file its package installs, and the
graph's launch file has a launch argument for every parameter the manager declares, with the
node's default. The files are read with `ast`; the manager's parameters from the real node."""

import ast
import glob
import os

from experiment_manager.commands.launcher import WORKER_NODES
from experiment_manager.graph.experiment_manager_node import ExperimentManagerNode
import rclpy
from rclpy.node import Node

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src')
LAUNCH_FILES = sorted(glob.glob(os.path.join(SRC, '*', 'launch', '*_launch.py')))


def _calls(path: str, name: str) -> list[ast.Call]:
    tree = ast.parse(open(path).read(), path)
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)
            and getattr(n.func, 'id', getattr(n.func, 'attr', None)) == name]


def _arguments(path: str) -> dict[str, str | None]:
    """The launch arguments a file declares: name -> default value (None: not a literal)."""
    def literal(node: ast.expr):
        return ast.literal_eval(node) if isinstance(node, ast.Constant) else None
    return {ast.literal_eval(c.args[0]): next((literal(k.value) for k in c.keywords
                                               if k.arg == 'default_value'), None)
            for c in _calls(path, 'DeclareLaunchArgument')}


def _nodes(path: str) -> list[dict[str, ast.expr]]:
    return [{k.arg: k.value for k in c.keywords} for c in _calls(path, 'Node')]


def _started(path: str) -> set[tuple[str, str]]:
    """(package, executable) of the nodes a file starts, where both are literals."""
    return {(ast.literal_eval(n['package']), ast.literal_eval(n['executable']))
            for n in _nodes(path) if isinstance(n.get('package'), ast.Constant)
            and isinstance(n.get('executable'), ast.Constant)}


def test_every_node_of_the_graph_has_its_own_launch_file():
    own = {os.path.basename(os.path.dirname(os.path.dirname(p))): _started(p)
           for p in LAUNCH_FILES if not p.endswith('experiment_launch.py')}
    for package, executable in WORKER_NODES:
        assert (package, executable) in own.get(package, set()), (
            f'no launch file in src/{package}/launch starts {executable}')


def test_a_worker_node_launch_file_defaults_to_its_installed_parameter_file():
    for path in LAUNCH_FILES:
        if path.endswith('experiment_launch.py'):
            continue
        assert set(_arguments(path)) == {'namespace', 'params_file'}, path
        joins = [c for c in _calls(path, 'join') if len(c.args) == 3]
        assert joins, f'{path}: no default parameter file'
        config, name = (ast.literal_eval(a) for a in joins[0].args[1:])
        assert os.path.isfile(os.path.join(os.path.dirname(os.path.dirname(path)), config,
                                           name)), f'{path}: {config}/{name} is not installed'


def test_the_graph_launch_file_sets_every_parameter_of_the_manager():
    path = os.path.join(SRC, 'experiment_manager', 'launch', 'experiment_launch.py')
    arguments = _arguments(path)
    rclpy.init()
    try:
        plain, node = Node('plain'), ExperimentManagerNode()
        try:    # the manager's own, not those every rclpy node has (use_sim_time, ...)
            declared = {name: p.value for name, p in node.get_parameters_by_prefix('').items()
                        if not plain.has_parameter(name)}
        finally:
            node.destroy_node()
            plain.destroy_node()
    finally:
        rclpy.shutdown()
    missing = sorted(set(declared) - set(arguments))
    assert not missing, f'experiment_launch.py has no launch argument for {missing}'
    for name, value in declared.items():
        default = arguments[name]
        if name == 'workers':       # a count there, the namespaces here
            assert int(default) == 1
        elif isinstance(value, list):   # '': the node's own default
            assert default == '', name
        else:
            assert type(value)(default) == value, (name, default, value)
