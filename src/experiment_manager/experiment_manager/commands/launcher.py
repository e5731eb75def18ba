"""Starting the graph's nodes as processes, from their installed executables (where `ros2 run`
finds them), each logging to its own file. No rclpy here."""

import ctypes
import os
import signal
import subprocess

from ament_index_python.packages import get_package_prefix, PackageNotFoundError

# The nodes of one worker, and the manager: (package, executable).
WORKER_NODES = (('pick_sim_world', 'world'), ('pick_validity', 'validity'),
                ('feeder_controller', 'feeder_controller'))
MANAGER = ('experiment_manager', 'experiment_manager')
READS_MESHES = {'world', 'validity'}    # the worker nodes with a `mesh_dirs` parameter
PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """In the child before exec: get SIGINT when the parent dies, even by SIGKILL, so that a
    killed `run` leaves no node behind (Linux)."""
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGINT)


def executable(package: str, name: str) -> str:
    """The installed executable `ros2 run package name` runs. Raises FileNotFoundError."""
    try:
        path = os.path.join(get_package_prefix(package), 'lib', package, name)
    except PackageNotFoundError:
        raise FileNotFoundError(f"package {package} is not installed (source the workspace's "
                                'install/setup.bash)') from None
    if not os.access(path, os.X_OK):
        raise FileNotFoundError(f'{path} is not an installed executable')
    return path


class NodeProcess:
    """A node started as a process, its output in `log_path`. stop() sends SIGINT, then
    SIGKILL after `timeout`, and returns the exit code. `label` names it in messages (default:
    the executable's name). `prefix`: a command that runs the node (it must exec it, so that
    the signals reach the node), e.g. `ip netns exec NS env VAR=value` for a node on another
    network host."""

    def __init__(self, package: str, name: str, ros_args: list[str], log_path: str,
                 label: str = '', append: bool = False, prefix: tuple[str, ...] = ()) -> None:
        self.name = label or name
        self._args = (package, name, ros_args, log_path, label)
        self._prefix = tuple(prefix)
        self.command = [*prefix, executable(package, name), '--ros-args', *ros_args]
        self.log_path = log_path
        with open(log_path, 'ab' if append else 'wb') as log:
            # A native crash (SIGSEGV in PyBullet, FCL or rcl) then leaves every thread's
            # Python stack in the log instead of nothing.
            self.process = subprocess.Popen(self.command, stdout=log, stderr=subprocess.STDOUT,
                                            stdin=subprocess.DEVNULL,
                                            preexec_fn=_die_with_parent,
                                            env={**os.environ, 'PYTHONFAULTHANDLER': '1'})

    def respawn(self) -> 'NodeProcess':
        """The same node started again, its output appended to the same log."""
        return NodeProcess(*self._args, append=True, prefix=self._prefix)

    @property
    def pid(self) -> int:
        return self.process.pid

    def running(self) -> bool:
        return self.process.poll() is None

    def stop(self, timeout: float = 20.0) -> int:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        return self.process.returncode

    def output(self, tail: int | None = None) -> str:
        """The process's output so far (its last `tail` lines)."""
        try:
            with open(self.log_path, encoding='utf-8', errors='replace') as f:
                lines = f.read().splitlines()
        except OSError:
            return ''
        return '\n'.join(lines[-tail:] if tail else lines)

    def describe_exit(self) -> str:
        code = self.process.returncode
        how = (f'was killed by signal {-code}' if code is not None and code < 0
               else f'exited with code {code}')
        return f'{self.name} (pid {self.pid}) {how}; its log is {self.log_path}'
