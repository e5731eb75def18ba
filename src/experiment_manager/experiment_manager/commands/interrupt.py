"""SIGINT and SIGTERM for the commands (`run`, `replay`): a flag that their loop checks between
two steps, never an exception raised wherever the main thread happens to be.

Raised by the signal handler itself, KeyboardInterrupt lands inside rclpy's executor (and
leaves a callback half done) or between a publish and the count of what was published (replay
then said "stopped after 0 messages" of a message a subscriber had received). Commands that use
this pass `SignalHandlerOptions.NO` to `rclpy.init`: rclpy's own handler would shut the context
down before the command could cancel its run or close its files.
"""

import signal
import threading

_STOP = threading.Event()


def _set(signum, frame) -> None:
    _STOP.set()


def install() -> None:
    """From now on SIGINT and SIGTERM only set the flag."""
    signal.signal(signal.SIGINT, _set)
    signal.signal(signal.SIGTERM, _set)


def check() -> None:
    """Raise KeyboardInterrupt if a signal came since the last check. The flag is cleared: a
    second signal (say, during the wait for a canceled run) is a new one."""
    if _STOP.is_set():
        _STOP.clear()
        raise KeyboardInterrupt


def sleep(seconds: float) -> None:
    """time.sleep that a signal ends at once (then KeyboardInterrupt)."""
    if seconds > 0:
        _STOP.wait(seconds)
    check()
