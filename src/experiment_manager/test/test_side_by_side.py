"""Runs side by side on shared workers (running/workers.py): the first begun takes a free
worker first, a later one fills what it leaves idle, and each gives the results it gives
alone."""

import os
import threading

from experiment_manager import experiment_file
from experiment_manager.analysis.results import read_text_rows, ResultsWriter
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
from experiment_manager.running.workers import Workers

FILE = """id: {id}
seed: {seed}
part: {{model: to220}}
experiments:
  - {{id: drop, type: drop_test, iterations: {n}, height_mm: 40}}
"""
HANG = 300.0    # s: a guard against a hang only (the gate opens as soon as B runs)


class Run:
    """A run as Workers sees it: whether it has an iteration ready for a backend."""

    def __init__(self, ready_for=()) -> None:
        self.ready_for = list(ready_for)

    def wants(self, backend) -> bool:
        return any(b is backend for b in self.ready_for)


def test_the_run_begun_first_takes_a_free_worker_first():
    workers, backend, other = Workers(), object(), object()
    first, second = Run([backend]), Run([backend, other])
    workers.join(first)
    workers.join(second)
    assert workers.free(backend, first) and not workers.free(backend, second)
    assert workers.free(other, second)          # the first has nothing for it
    first.ready_for = []                         # the first has nothing ready: the second may
    assert workers.free(backend, second)
    workers.take(backend, second)
    assert not workers.free(backend, first)      # held for the iteration in flight
    assert workers.holder(backend) is second
    workers.put_back(backend)
    assert workers.free(backend, first) and workers.holder(backend) is None
    workers.leave(first)
    assert workers.free(backend, second)


class Gated(LocalBackend):
    """A worker in this process whose reset for run `a` waits until a reset for run `b` began
    on any worker (`b_ran`), and says when run `a` reached it (`a_waits`)."""

    def __init__(self, workers: Workers, runs: dict, events: dict) -> None:
        super().__init__()
        self.workers, self.runs, self.events = workers, runs, events

    def reset(self, container, seed) -> None:
        holder = self.workers.holder(self)
        if holder is self.runs.get('b'):
            self.events['b_ran'].set()
        elif holder is self.runs.get('a'):
            self.events['a_waits'].set()
            if not self.events['b_ran'].wait(HANG):
                raise AssertionError('the later run never took the idle worker')
        super().reset(container, seed)


def read(directory: str) -> list[dict]:
    return read_text_rows(os.path.join(directory, 'iterations.csv'), drop=('wall_time',))


def _alone(text: str, directory: str) -> list[dict]:
    file = experiment_file.parse(text)
    with LocalBackend() as backend, ResultsWriter(directory, file.text) as writer:
        Runner(file, [backend], writer).run()
    return read(directory)


def test_a_later_run_fills_the_worker_an_earlier_one_leaves_idle(tmp_path):
    a_text = FILE.format(id='a', seed=1, n=1)       # one iteration: one worker left idle
    b_text = FILE.format(id='b', seed=2, n=3)
    workers = Workers()
    runs: dict = {}
    events = {'a_waits': threading.Event(), 'b_ran': threading.Event()}
    backends = [Gated(workers, runs, events) for _ in range(2)]
    summaries, errors = {}, []

    def run(name: str, text: str) -> None:
        file = experiment_file.parse(text)
        try:
            with ResultsWriter(str(tmp_path / name), file.text) as writer:
                runner = runs[name] = Runner(file, backends, writer, workers=workers)
                summaries[name] = runner.run()
        except BaseException as exc:    # noqa: B036 - the test thread reports it
            errors.append(exc)
            events['b_ran'].set()

    try:
        a = threading.Thread(target=run, args=('a', a_text))
        a.start()
        assert events['a_waits'].wait(HANG)     # a's one iteration is in flight
        b = threading.Thread(target=run, args=('b', b_text))
        b.start()
        a.join()
        b.join()
    finally:
        for backend in backends:
            backend.close()
    assert not errors, errors
    # the gate opened: b ran on the worker a left idle while a's iteration waited
    assert events['b_ran'].is_set() and set(summaries) == {'a', 'b'}
    assert read(str(tmp_path / 'a')) == _alone(a_text, str(tmp_path / 'a1'))
    assert read(str(tmp_path / 'b')) == _alone(b_text, str(tmp_path / 'b1'))


class Held(LocalBackend):
    """A worker in this process whose resets wait until `release` is set, counting those
    waiting in `waiting` (a semaphore released once per reset begun)."""

    def __init__(self, release: threading.Event, waiting: threading.Semaphore) -> None:
        super().__init__()
        self.release, self.waiting = release, waiting

    def reset(self, container, seed) -> None:
        self.waiting.release()
        if not self.release.wait(HANG):
            raise AssertionError('never released')
        super().reset(container, seed)


def test_a_run_waiting_for_a_worker_ends_at_once_when_stopped(tmp_path):
    release, waiting = threading.Event(), threading.Semaphore(0)
    workers = Workers()
    backends = [Held(release, waiting) for _ in range(2)]
    files = {name: experiment_file.parse(FILE.format(id=name, seed=k, n=4))
             for k, name in enumerate(('a', 'b'))}
    ended: dict[str, BaseException | None] = {}
    runners = {name: Runner(f, backends, ResultsWriter(str(tmp_path / name), f.text),
                            workers=workers, rank=k) for k, (name, f) in enumerate(files.items())}

    def run(name: str) -> None:
        try:
            runners[name].run()
            ended[name] = None
        except BaseException as exc:    # noqa: B036 - the test thread reports it
            ended[name] = exc

    threads = {name: threading.Thread(target=run, args=(name,)) for name in files}
    try:
        threads['a'].start()
        assert waiting.acquire(timeout=HANG) and waiting.acquire(timeout=HANG)   # a holds both
        threads['b'].start()
        canceled = RuntimeError('canceled')
        runners['b'].stop(canceled)
        threads['b'].join(HANG)
        # b ended while a still held both workers: it waited for none of a's iterations
        assert ended.get('b') is canceled and not release.is_set()
        release.set()
        threads['a'].join(HANG)
        assert ended.get('a', 'not ended') is None
    finally:
        release.set()
        for backend in backends:
            backend.close()
        for runner in runners.values():
            runner.sink.close()
    assert read(str(tmp_path / 'b')) == []
    assert len(read(str(tmp_path / 'a'))) == 4
