import os
import signal
import threading
import time

from experiment_manager.commands import interrupt
import pytest


@pytest.fixture
def installed():
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    interrupt.install()
    yield
    for s, handler in saved.items():
        signal.signal(s, handler)


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_a_signal_is_raised_where_the_command_checks_and_not_before(installed, signum):
    os.kill(os.getpid(), signum)
    done = ['this line ran']        # time.sleep's signal would have raised before it
    with pytest.raises(KeyboardInterrupt):
        interrupt.check()
    interrupt.check()               # the flag was cleared: one signal, one stop
    assert done


def test_a_signal_ends_a_sleep_at_once(installed):
    timer = threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        interrupt.sleep(30.0)
    assert time.monotonic() - start < 10.0
    interrupt.sleep(0.0)            # no signal: returns
    interrupt.sleep(-1.0)           # a due time already past: returns
