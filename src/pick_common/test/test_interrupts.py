"""A node's executable holds SIGINT and SIGTERM before it imports its node (interrupts.start):
a signal that comes while the node's modules still import is noted, not raised inside an
import, and node_runner.run then stops the node cleanly. Run in a fresh interpreter, with a
stand-in node module that signals its own process while it is imported."""

import signal
import subprocess
import sys
import textwrap

import pytest

NODE_MODULE = """
import os, signal, sys
from pick_common import interrupts
os.kill(os.getpid(), getattr(signal, sys.argv[1]))   # while this module is imported
import json                                           # the imports go on

def main():
    print('noted', [signal.Signals(s).name for s in interrupts.received])
"""


@pytest.mark.parametrize('signum', ['SIGINT', 'SIGTERM'])
def test_a_signal_while_the_node_imports_is_noted_not_raised(tmp_path, signum):
    (tmp_path / 'standin_node.py').write_text(textwrap.dedent(NODE_MODULE))
    code = 'from pick_common import interrupts; interrupts.start("standin_node")'
    done = subprocess.run([sys.executable, '-c', code, signum], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"noted ['{signum}']"


@pytest.mark.parametrize('signum', ['SIGINT', 'SIGTERM'])
def test_the_check_above_can_fail(tmp_path, signum):
    # the same module imported without holding the signals dies of it
    (tmp_path / 'standin_node.py').write_text(textwrap.dedent(NODE_MODULE))
    done = subprocess.run([sys.executable, '-c', 'import standin_node', signum], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode != 0
    assert done.returncode in (-getattr(signal, signum), 1)   # KeyboardInterrupt: 1 or -2
