"""Every package's package.xml declares what its code imports, and only keys that rosdep can
resolve, so that `rosdep install --from-paths src --ignore-src` works on a full ROS install.
The imports are read with `ast` from each package's module, launch files and tests:
module and launch imports must be run dependencies (`exec_depend` or `depend`), test imports
run or test dependencies."""

import ast
import os
import sys
import xml.etree.ElementTree as ET

import pytest

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src')

# What a top-level import needs, as a rosdep key or a ROS package name. None: no rosdep key
# exists (mcap, mcap_ros2, coacd and markdown_it are on PyPI only); requirements.txt installs
# them, and a comment in the package.xml says so.
IMPORT_KEYS = {
    'numpy': 'python3-numpy',
    'scipy': 'python3-scipy',
    'yaml': 'python3-yaml',
    'pydantic': 'python3-pydantic',
    'pydantic_core': 'python3-pydantic',     # pydantic's own core, installed with it
    'matplotlib': 'python3-matplotlib',
    'mpl_toolkits': 'python3-matplotlib',   # matplotlib's 3D axes, shipped with it
    'tqdm': 'python3-tqdm',
    'pytest': 'python3-pytest',
    'hypothesis': 'python3-hypothesis',
    'jsonschema': 'python3-jsonschema',
    'trimesh': 'python3-trimesh-pip',
    'networkx': 'python3-networkx',         # imported by trimesh (split, fill_holes)
    'fcl': 'python-fcl-pip',
    'pybullet': 'python3-pybullet-pip',
    'mcap': None,
    'mcap_ros2': None,
    'coacd': None,
    'cascadio': None,                       # OpenCASCADE's STEP reader (solids.py)
    'markdown_it': None,
}
# ROS 2 Jazzy packages imported under their own names.
ROS_PACKAGES = {
    'rclpy', 'launch', 'launch_ros', 'ament_index_python', 'action_msgs', 'builtin_interfaces',
    'geometry_msgs', 'rcl_interfaces', 'rosgraph_msgs', 'shape_msgs', 'std_msgs',
    'tf2_msgs', 'visualization_msgs',
}
# Keys a package.xml may name beyond the two sets above: the build tools of the interface
# package, and the rosdep keys in IMPORT_KEYS. The pip keys are the names in rosdistro's
# rosdep/python.yaml (`python3-pybullet` and `python3-fcl-pip` are not keys there).
BUILD_KEYS = {'ament_cmake', 'rosidl_default_generators', 'rosidl_default_runtime'}
ROSDEP_KEYS = {key for key in IMPORT_KEYS.values() if key}


def _workspace() -> dict[str, str]:
    """package name -> its directory, for every package.xml under src/."""
    found = {}
    for entry in sorted(os.listdir(SRC)):
        path = os.path.join(SRC, entry, 'package.xml')
        if os.path.exists(path):
            found[ET.parse(path).getroot().findtext('name')] = os.path.join(SRC, entry)
    return found


WORKSPACE = _workspace()
PYTHON_PACKAGES = sorted(name for name, path in WORKSPACE.items()
                         if os.path.exists(os.path.join(path, 'setup.py')))


def _depends(path: str) -> tuple[set[str], set[str]]:
    """(run dependencies, test dependencies) of a package.xml."""
    root = ET.parse(os.path.join(path, 'package.xml')).getroot()
    run = {e.text.strip() for e in root if e.tag in ('depend', 'exec_depend')}
    test = {e.text.strip() for e in root if e.tag == 'test_depend'}
    return run, test


def _imports(directory: str) -> dict[str, str]:
    """Top-level names imported by the .py files under `directory` -> a file that imports it."""
    found: dict[str, str] = {}
    if not os.path.isdir(directory):
        return found
    for here, _, files in os.walk(directory):
        for name in sorted(files):
            if not name.endswith('.py'):
                continue
            path = os.path.join(here, name)
            with open(path, encoding='utf-8') as f:
                tree = ast.parse(f.read(), path)
            for node in ast.walk(tree):
                if isinstance(node, ast.Import):
                    tops = [alias.name.split('.')[0] for alias in node.names]
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    tops = [node.module.split('.')[0]]
                else:
                    continue
                for top in tops:
                    found.setdefault(top, os.path.relpath(path, SRC))
    return found


def _needed(imports: dict[str, str], own: str) -> dict[str, str]:
    """The keys the imports need -> a file that needs it. Fails on an import nobody mapped."""
    needed = {}
    for top, path in imports.items():
        if top in sys.stdlib_module_names or top in ('setuptools', own):
            continue
        if top in IMPORT_KEYS:
            key = IMPORT_KEYS[top]
        elif top in ROS_PACKAGES or top in WORKSPACE:
            key = top
        else:
            pytest.fail(f'{path} imports {top!r}, which tests/test_manifests.py does not map to '
                        'a rosdep key: add it to IMPORT_KEYS or ROS_PACKAGES')
        if key is not None:
            needed.setdefault(key, path)
    return needed


def test_every_python_package_is_checked():
    assert PYTHON_PACKAGES == ['experiment_manager', 'feeder_controller', 'pick_common',
                               'pick_sim_world', 'pick_validity']


@pytest.mark.parametrize('package', PYTHON_PACKAGES)
def test_the_manifest_declares_what_the_code_imports(package):
    path = WORKSPACE[package]
    run, test = _depends(path)
    code = {**_imports(os.path.join(path, package)), **_imports(os.path.join(path, 'launch'))}
    missing = {key: where for key, where in _needed(code, package).items() if key not in run}
    assert not missing, f'{package}/package.xml lacks exec_depend for: ' + ', '.join(
        f'{key} ({where})' for key, where in sorted(missing.items()))
    tests = _imports(os.path.join(path, 'test'))
    missing = {key: where for key, where in _needed(tests, package).items()
               if key not in run | test}
    assert not missing, f'{package}/package.xml lacks test_depend for: ' + ', '.join(
        f'{key} ({where})' for key, where in sorted(missing.items()))


@pytest.mark.parametrize('package', sorted(WORKSPACE))
def test_every_key_of_the_manifest_resolves(package):
    run, test = _depends(WORKSPACE[package])
    known = ROSDEP_KEYS | ROS_PACKAGES | BUILD_KEYS | set(WORKSPACE)
    unknown = sorted((run | test) - known)
    assert not unknown, f'{package}/package.xml names keys rosdep does not resolve: {unknown}'


def test_the_check_maps_imports_to_their_keys(tmp_path):
    # The check itself: submodule and from-imports count, the standard library and relative
    # imports do not, and an import nobody mapped fails the test.
    (tmp_path / 'mod.py').write_text('import os.path\nimport scipy.spatial\nfrom numpy import '
                                     'array\nfrom . import sibling\n')
    assert set(_needed(_imports(str(tmp_path)), 'mine')) == {'python3-scipy', 'python3-numpy'}
    (tmp_path / 'other.py').write_text('import not_a_known_library\n')
    with pytest.raises(pytest.fail.Exception, match="imports 'not_a_known_library'"):
        _needed(_imports(str(tmp_path)), 'mine')
