"""Fixtures for graph tests: a private ROS domain, node processes, a client node."""

from collections.abc import Callable, Iterator
import os
import signal

from fuzz import TRIED
from graph import Client, NodeProcess
import pytest


def pytest_configure(config) -> None:
    """A test run started in the background of a non-interactive shell (`(cmd &)`) inherits
    SIGINT ignored, and an ignored signal stays ignored across exec: every run and node process
    the tests start would then ignore the SIGINT the tests send (seen: the stopped-run test's run
    finished with 0 instead of 130). A Python handler is reset to the default on exec, so with
    it the processes the tests start get SIGINT as a user's shell delivers it."""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_terminal_summary(terminalreporter) -> None:
    """The requests the fuzz tests sent, per endpoint, by the error code of the answer."""
    if TRIED:
        terminalreporter.section('requests fuzzed per endpoint')
        for endpoint, codes in TRIED.items():
            terminalreporter.write_line(f'{endpoint}: {sum(codes.values())} ('
                                        + ', '.join(f'{c} {n}' for c, n in codes.items()) + ')')


@pytest.fixture(scope='session', autouse=True)
def private_ros_domain() -> Iterator[int]:
    """A ROS domain of this test run only, on loopback: parallel runs do not see each other."""
    domain = int(os.environ.get('PICK_TEST_DOMAIN', 10 + os.getpid() % 90))
    saved = {k: os.environ.get(k) for k in ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE')}
    os.environ['ROS_DOMAIN_ID'] = str(domain)
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    yield domain
    for key, value in saved.items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value


@pytest.fixture
def start_node() -> Iterator[Callable[..., NodeProcess]]:
    started: list[NodeProcess] = []

    def start(package: str, name: str, *args: str) -> NodeProcess:
        started.append(NodeProcess(package, name, list(args)))
        return started[-1]

    yield start
    for proc in started:
        proc.stop()


@pytest.fixture
def client() -> Iterator[Client]:
    c = Client()
    yield c
    c.close()
