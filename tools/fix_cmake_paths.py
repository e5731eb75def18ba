"""Point the ROS wheels' exported CMake files at this venv's include directories.

The ros-* wheels were built under /opt/python/cp311-cp311 and their *Export.cmake files name
that interpreter's include directories. CMake refuses to generate while those paths do not
exist (see ROS_WHEELS.md, step 3). This rewrites them, inside the venv only, to the running
interpreter's include directory and numpy's. Idempotent.
"""

import pathlib
import sys
import sysconfig

import numpy

BUILD_PREFIX = '/opt/python/cp311-cp311'
REPLACEMENTS = (
    (f'{BUILD_PREFIX}/lib/python3.11/site-packages/numpy/_core/include', numpy.get_include()),
    (f'{BUILD_PREFIX}/include/python3.11', sysconfig.get_paths()['include']),
)


def main() -> int:
    share = pathlib.Path(sys.prefix) / 'share'
    changed = 0
    for path in sorted(share.glob('*/cmake/*.cmake')):
        text = path.read_text()
        new = text
        for old, replacement in REPLACEMENTS:
            new = new.replace(old, replacement)
        if new != text:
            path.write_text(new)
            changed += 1
    left = [p for p in share.glob('*/cmake/*.cmake') if BUILD_PREFIX in p.read_text()]
    print(f'fix_cmake_paths: rewrote {changed} file(s) under {share}')
    if left:
        print(f'fix_cmake_paths: {BUILD_PREFIX} still named in: {[str(p) for p in left]}')
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
