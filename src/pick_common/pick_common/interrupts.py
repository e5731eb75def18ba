"""The signals that stop a node's process, noted from its first instruction until rclpy handles
them. A node's executable holds them (`hold`) before it imports anything heavy: a SIGINT that
came while the world still imported PyBullet and SciPy raised KeyboardInterrupt inside an
extension's initialisation, and the process died of SIGINT, of SIGSEGV or hung (4 of 4 tries
with the signal sent while the world still imported). node_runner.run reads `received` once
after rclpy.init and stops the node cleanly if anything came. Standard library only."""

import importlib
import signal

received: list[int] = []    # every signal the handler saw, in order


def record(signum: int, frame) -> None:
    """The Python handler of SIGINT (and, until rclpy.init, SIGTERM): note the signal, nothing
    else. It calls nothing of rclpy: Python runs it between two bytecodes of the main thread,
    once inside Context.ok() with the context's lock held, and a handler that asked rclpy.ok()
    waited for that lock for ever (a world still up 30 s after SIGINT, its stack in
    Context.ok twice, in CI). Under rclpy's handler, which shuts the context down and then
    calls this one, the spin loop sees the shutdown."""
    received.append(signum)


def hold() -> None:
    """Note SIGINT and SIGTERM from now on instead of dying of them (rclpy.init puts its own
    handlers in front, and they call this one)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, record)


def start(module: str) -> None:
    """A node's executable: hold the signals, then import `module` (a node's, with a main()
    that calls node_runner.run) and run its main()."""
    hold()
    importlib.import_module(module).main()
