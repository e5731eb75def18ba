"""A worker's nodes to call through the graph, and the working time of a full run from its run
directories, for the benchmarks; the test case's files and a run of a variant of one on the
cores are studies.cases', which the benchmarks share (`TEST_CASE`, `variant`, `run_on_cores`
are imported here from it)."""

from collections.abc import Iterator, Sequence
import contextlib
import os
import re
import tempfile

from experiment_manager.analysis.results import read_csv
from experiment_manager.commands.launcher import NodeProcess, WORKER_NODES
from experiment_manager.graph.recording import CompleteRecords
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Message
from studies.cases import run_on_cores, summarise_on_cores, TEST_CASE, variant  # noqa: F401


@contextlib.contextmanager
def one_worker(label: str, world_args: Sequence[str] = ()) -> Iterator[str]:
    """A worker's nodes (world, validity, feeder_controller) as processes on a private domain
    of this process (ROS_DOMAIN_ID unless set, this host only), under `worker_0` of the
    namespace yielded (`/<label>_<pid>`); `world_args` are the world's extra ROS arguments.
    Stopped when the block ends."""
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    ns = f'/{label}_{os.getpid()}'
    logs = tempfile.mkdtemp(prefix=f'{label}_logs_')
    procs = [NodeProcess(pkg, exe, ['-r', f'__ns:={ns}/worker_0',
                                    *(world_args if exe == 'world' else ())],
                         f'{logs}/{exe}.log') for pkg, exe in WORKER_NODES]
    try:
        yield ns
    finally:
        for p in procs:
            p.stop()


def recorded_spans(run_dir: str) -> list[float]:
    """Seconds from the first message to the last of each recording of a run directory
    (recording.mcap, then recording_<k>.mcap of each --resume): the run's working time
    without the gaps between an interruption and its resume, nor the start of the processes
    and the report. A recording cut off by a kill is read up to its tear."""
    names = sorted((n for n in os.listdir(run_dir) if re.fullmatch(r'recording(_\d+)?\.mcap', n)),
                   key=lambda n: int(re.sub(r'\D', '', n) or 1))
    spans = []
    for name in names:
        with open(os.path.join(run_dir, name), 'rb') as f:
            try:
                summary = make_reader(f).get_summary()
            except McapError:               # cut off: no footer
                summary = None
            if summary is not None and summary.statistics is not None:
                stats = summary.statistics
                first, last = stats.message_start_time, stats.message_end_time
            else:
                f.seek(0)
                first, last = None, None
                for record in CompleteRecords(f):
                    if isinstance(record, Message):
                        first = record.log_time if first is None else first
                        last = record.log_time
        if first is not None:
            spans.append((last - first) / 1e9)
    return spans


def print_full_case(run_dirs: list[str]) -> None:
    """The working time of the paper's full test case from its run directories."""
    total = 0.0
    for run_dir in run_dirs:
        spans = recorded_spans(run_dir)
        iterations = len(read_csv(os.path.join(run_dir, 'iterations.csv')))
        total += sum(spans)
        print(f'{os.path.basename(run_dir.rstrip("/"))}: {iterations} iterations, '
              f'{sum(spans) / 60:.1f} min in {len(spans)} segment(s) '
              f'({", ".join(f"{s / 60:.1f}" for s in spans)})')
    print(f"the paper's test case, full counts: {total / 60:.1f} min of recorded work "
          f'({total / 3600:.2f} h; starting the processes and the reports not included)')
