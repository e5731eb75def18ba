"""The manager's rooms and the order they may import each other in (the package docstring):
experiment_file, analysis, running, graph, commands, each importing only those before it; the
first three never import rclpy, so a run's logic is tested and used without a ROS graph."""

import ast
import os
import subprocess
import sys

import experiment_manager
import pytest

ORDER = ('experiment_file', 'analysis', 'running', 'graph', 'commands')
PACKAGE = os.path.dirname(experiment_manager.__file__)


def _imported_rooms(path: str) -> set[str]:
    """The rooms of experiment_manager that a module imports, relative or absolute."""
    tree = ast.parse(open(path, encoding='utf-8').read())
    rooms = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level == 2 and node.module:           # from ..room.module import x
                rooms.add(node.module.split('.')[0])
            elif node.level == 2:                          # from .. import room
                rooms.update(a.name for a in node.names)
            elif node.level == 0 and (node.module or '').startswith('experiment_manager.'):
                rooms.add(node.module.split('.')[1])
    return rooms & set(ORDER)


def test_every_module_lives_in_a_room():
    loose = [f for f in os.listdir(PACKAGE) if f.endswith('.py') and f != '__init__.py']
    assert loose == []
    assert sorted(d for d in os.listdir(PACKAGE)
                  if os.path.isdir(os.path.join(PACKAGE, d)) and d != '__pycache__') \
        == sorted(ORDER)


@pytest.mark.parametrize('room', ORDER)
def test_a_room_imports_only_the_rooms_before_it(room):
    allowed = set(ORDER[:ORDER.index(room) + 1])
    for name in os.listdir(os.path.join(PACKAGE, room)):
        if name.endswith('.py'):
            found = _imported_rooms(os.path.join(PACKAGE, room, name))
            assert found <= allowed, f'{room}/{name} imports {sorted(found - allowed)}'


def _relative_targets(path: str, room: str) -> list[str]:
    """The modules or rooms (paths relative to the package, no .py) that the relative
    imports of a module name, nested ones (a lazy import) too."""
    tree = ast.parse(open(path, encoding='utf-8').read())
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom) or node.level == 0:
            continue
        base = room if node.level == 1 else ''
        if node.module:
            out.append(os.path.join(base, *node.module.split('.')))
        else:
            out += [os.path.join(base, a.name) for a in node.names]
    return out


@pytest.mark.parametrize('room', ORDER)
def test_every_relative_import_names_a_module_that_is_there(room):
    # a lazy import inside a function is not run by importing the module: checked here
    for name in os.listdir(os.path.join(PACKAGE, room)):
        if name.endswith('.py'):
            for target in _relative_targets(os.path.join(PACKAGE, room, name), room):
                there = os.path.isdir(os.path.join(PACKAGE, target)) or os.path.isfile(
                    os.path.join(PACKAGE, target + '.py'))
                assert there, f'{room}/{name} imports {target}, which is not there'


def test_the_check_sees_an_upward_import(tmp_path):
    # The check above can fail: a module of analysis that imports from running is seen.
    path = tmp_path / 'upward.py'
    path.write_text('from ..running.scheduler import Runner\n\n\ndef f():\n'
                    '    from . import pictures\n')
    assert _imported_rooms(str(path)) == {'running'}
    assert _relative_targets(str(path), 'graph') == ['running/scheduler', 'graph/pictures']


@pytest.mark.parametrize('room', ORDER[:3])
def test_the_pure_rooms_do_not_import_rclpy(room):
    modules = [f'experiment_manager.{room}.{n[:-3]}'
               for n in sorted(os.listdir(os.path.join(PACKAGE, room)))
               if n.endswith('.py') and n != '__init__.py']
    code = (f'import sys, {", ".join(modules)}; '
            'print(" ".join(sorted({m.split(".")[0] for m in sys.modules})))')
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          check=True)
    assert 'rclpy' not in done.stdout.split()
