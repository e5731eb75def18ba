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


def _modules(room: str) -> list[tuple[str, str]]:
    """(path, dotted name under the package) of every module of a room, its subpackages'
    too (experiment_file/kinds/bins.py is experiment_file.kinds.bins)."""
    out = []
    for top, dirs, files in os.walk(os.path.join(PACKAGE, room)):
        dirs[:] = sorted(d for d in dirs if d != '__pycache__')
        for name in sorted(files):
            if name.endswith('.py'):
                parts = os.path.relpath(os.path.join(top, name), PACKAGE)[:-3].split(os.sep)
                out.append((os.path.join(top, name), '.'.join(parts)))
    return out


def _targets(path: str, module: str) -> list[str]:
    """The modules a module imports, as dotted names under the package (relative imports
    resolved from the module's own package, nested ones (a lazy import) too; absolute
    imports of experiment_manager likewise); others left out."""
    package = module.split('.')[:-1]        # an __init__'s package is its own folder
    tree = ast.parse(open(path, encoding='utf-8').read())
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level == 0:
            if (node.module or '').startswith('experiment_manager.'):
                out.append(node.module.removeprefix('experiment_manager.'))
            continue
        base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
        if node.module:
            out.append('.'.join(base + node.module.split('.')))
        else:
            out += ['.'.join(base + [a.name]) for a in node.names]
    return out


def _imported_rooms(path: str, module: str = 'graph.x') -> set[str]:
    """The rooms of experiment_manager that a module imports, relative or absolute."""
    return {t.split('.')[0] for t in _targets(path, module)} & set(ORDER)


def test_every_module_lives_in_a_room():
    loose = [f for f in os.listdir(PACKAGE) if f.endswith('.py') and f != '__init__.py']
    assert loose == []
    assert sorted(d for d in os.listdir(PACKAGE)
                  if os.path.isdir(os.path.join(PACKAGE, d)) and d != '__pycache__') \
        == sorted(ORDER)


@pytest.mark.parametrize('room', ORDER)
def test_a_room_imports_only_the_rooms_before_it(room):
    allowed = set(ORDER[:ORDER.index(room) + 1])
    for path, module in _modules(room):
        found = _imported_rooms(path, module)
        assert found <= allowed, f'{module} imports {sorted(found - allowed)}'


@pytest.mark.parametrize('room', ORDER)
def test_every_relative_import_names_a_module_that_is_there(room):
    # a lazy import inside a function is not run by importing the module: checked here
    for path, module in _modules(room):
        for target in _targets(path, module):
            where = os.path.join(PACKAGE, *target.split('.'))
            there = os.path.isdir(where) or os.path.isfile(where + '.py')
            # `from .module import name`: the name may be the module's, not a module
            parent = os.path.join(PACKAGE, *target.split('.')[:-1])
            named = os.path.isfile(parent + '.py') or os.path.isfile(
                os.path.join(parent, '__init__.py'))
            assert there or named, f'{module} imports {target}, which is not there'


def test_the_check_sees_an_upward_import(tmp_path):
    # The check above can fail: a module of analysis, or of a subpackage of it, that imports
    # from running is seen, a lazy import too.
    path = tmp_path / 'upward.py'
    path.write_text('from ..running.scheduler import Runner\n\n\ndef f():\n'
                    '    from . import pictures\n')
    assert _imported_rooms(str(path), 'analysis.upward') == {'analysis', 'running'}
    assert _targets(str(path), 'analysis.upward') == ['running.scheduler', 'analysis.pictures']
    path.write_text('from ...running import sampling\n')
    assert _imported_rooms(str(path), 'analysis.report.upward') == {'running'}


@pytest.mark.parametrize('room', ORDER[:3])
def test_the_pure_rooms_do_not_import_rclpy(room):
    modules = [f'experiment_manager.{m}' for _, m in _modules(room)]
    code = (f'import sys, {", ".join(modules)}; '
            'print(" ".join(sorted({m.split(".")[0] for m in sys.modules})))')
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          check=True)
    assert 'rclpy' not in done.stdout.split()
