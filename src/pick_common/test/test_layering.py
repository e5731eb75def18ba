"""The layering the packages promise: only the world imports PyBullet, so the validity node
serves a real cell without the simulator, and the feeder and manager nodes do not load it;
the pure modules of pick_common import neither rclpy nor PyBullet (trimesh loads python-fcl
by itself where it is installed, so FCL is not asserted absent where a part is built); and
what only names a part (its spec, the built-in models, the messages' conversions) does not
load the mesh stack."""

import subprocess
import sys

import pytest


def _loaded(module: str) -> set[str]:
    """The top-level modules a fresh interpreter has loaded after importing `module`."""
    code = (f'import sys, {module}; '
            'print(" ".join(sorted({m.split(".")[0] for m in sys.modules})))')
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          check=True)
    return set(done.stdout.split())


@pytest.mark.parametrize('module', [
    'pick_validity.validity_node',
    'feeder_controller.feeder_controller_node',
    'experiment_manager.graph.experiment_manager_node',
])
def test_nodes_other_than_the_world_do_not_import_pybullet(module):
    assert 'pybullet' not in _loaded(module)


def test_the_world_node_does_import_pybullet():
    # The check above can fail: the same probe sees PyBullet where it is imported.
    assert 'pybullet' in _loaded('pick_sim_world.world_node')


@pytest.mark.parametrize('module', ['pick_common.errors', 'pick_common.containers',
                                    'pick_common.parts.geometry', 'pick_common.specs',
                                    'pick_common.states'])
def test_pure_modules_import_neither_ros_nor_the_simulator(module):
    assert not _loaded(module) & {'rclpy', 'pybullet'}


@pytest.mark.parametrize('module', ['pick_common.parts.spec', 'pick_common.parts.models',
                                    'pick_common.parts.primitives', 'pick_common.specs',
                                    'pick_common.conversions', 'pick_validity.config'])
def test_what_only_names_a_part_does_not_load_the_mesh_stack(module):
    assert not _loaded(module) & {'trimesh', 'coacd', 'fcl'}


def test_the_mesh_stack_is_seen_where_it_is_loaded():
    # the check above can fail: the same probe sees trimesh where a part is built
    assert 'trimesh' in _loaded('pick_common.parts.geometry')

