"""One run of an experiment file through the graph, apart from the node that serves the goal:
the paths it may use, the run directory, the results writer, the recording, the run over the
workers, the pictures and the report, and the results attached to the recording.

The node maps a goal to a session and the session's exceptions to error codes; a session knows
nothing of goals.
"""

from collections.abc import Callable, Sequence
from datetime import datetime
import os
import threading
import traceback

from pick_common.errors import check_inside, InvalidArgument

from ..analysis import part_sheet, report
from ..analysis.results import keep_part_file, ResultsWriter
from ..analysis.summary import Summary
from ..experiment_file import ExperimentFile, load, resolved
from ..running.backend import Backend
from ..running.scheduler import Progress, Runner
from ..running.workers import Workers
from .recording import Recorder
from .topic_recorder import TopicRecorder

RESULT_FILES = ('iterations.csv', 'checks.csv', 'picks.csv', 'parts.csv', 'summary.json')


def run_directory(output_dir: str, file_id: str) -> str:
    """A new directory name <output_dir>/<id>_<YYYYmmdd-HHMMSS>[_k] that does not exist yet."""
    stamp = datetime.now().strftime('%Y%m%d-%H%M%S')
    base = os.path.join(os.path.abspath(os.path.expanduser(output_dir)), f'{file_id}_{stamp}')
    path, k = base, 1
    while os.path.exists(path):
        k += 1
        path = f'{base}_{k}'
    return path


class RunSession:
    """A run of one experiment file: `open` it, `run` it on backends, `write_report`, and
    always `close` it (which closes the recording with the results attached, and the files).

    experiment_dirs, output_dirs: where its files may be read and its run directory written
    (the node's parameters of those names). topics: the recorder of the workers' topics.
    """

    def __init__(self, experiment_dirs: Sequence[str], output_dirs: Sequence[str],
                 chunk_size: int, topics: TopicRecorder, node_name: str, logger) -> None:
        self._experiment_dirs, self._output_dirs = experiment_dirs, output_dirs
        self._chunk_size, self._topics = chunk_size, topics
        self._node_name, self._logger = node_name, logger
        self.file: ExperimentFile | None = None
        self.writer: ResultsWriter | None = None
        self.recorder: Recorder | None = None
        self.runner: Runner | None = None

    def open(self, experiment_file: str, output_dir: str, resume: bool) -> None:
        """Check and load the file, make (or, to resume, take) the run directory, open the
        results writer and the recording. Raises InvalidArgument naming what is wrong."""
        check_inside('experiment_file', experiment_file, self._experiment_dirs,
                     'experiment_dirs')
        file = self.file = load(experiment_file)
        if file.part.mesh_path:
            check_inside('part.mesh', file.part.mesh_path, self._experiment_dirs,
                         'experiment_dirs')
        if resume:
            if not output_dir:
                raise InvalidArgument('output_dir', '', 'must name the run directory to resume')
            run_dir = os.path.abspath(os.path.expanduser(output_dir))
        else:
            run_dir = run_directory(output_dir or file.output_dir, file.id)
        check_inside('output_dir', run_dir, self._output_dirs, 'output_dirs')
        self.writer = ResultsWriter(run_dir, file.text, resume)
        if not resume:
            keep_part_file(file.part.mesh_path, file.path, run_dir)
        if not os.path.exists(os.path.join(run_dir, resolved.NAME)):   # what it runs with, once
            resolved.write(file, run_dir)
        self.recorder = self._open_recording(run_dir, resume)

    @property
    def run_dir(self) -> str:
        return self.writer.directory

    def run(self, backends: Sequence[Backend], progress: Callable[[Progress], None],
            abort: threading.Event, names: Sequence[str], workers: Workers, rank: int,
            made: Callable[[Runner], None]) -> Summary:
        """Run the file on the backends (workers, named `names` in the log), shared through
        `workers` with the runs beside it, after those of a lower `rank`; the summary.
        `made` is given the runner before it runs (to stop it, Runner.stop)."""
        self._logger.info(f'running {self.file.path} into {self.run_dir} on {len(backends)} '
                          f'worker(s): {", ".join(names)}')
        runner = self.runner = Runner(self.file, backends, self.writer, progress, abort,
                                      workers, rank)
        made(runner)
        try:
            return runner.run()
        finally:
            for k in runner.lost_workers:
                self._logger.warning(f'worker {names[k]} was lost (missing at the start, or '
                                     'during the run)')
            for k in runner.rejoined:
                self._logger.warning(f'worker {names[k]} was lost and came back')

    def write_report(self) -> str:
        """The pictures and the report; '' when they could not be written (the results stand
        without them; the error is logged). Pictures need the simulator (pick_sim_world's
        renderer): a manager on a host without it writes the report without pictures."""
        try:
            try:
                from ..analysis import pictures  # imports PyBullet: only here, when made
                from ..running import resimulate
            except ImportError as exc:
                self._logger.warning(f'no pictures: {exc}')
            else:
                pictures.write(self.file, self.run_dir,
                               {'spill.png': resimulate.spill_picture})
            part_sheet.write_account(self.file, self.run_dir)
            return report.write(self.run_dir)
        except Exception as exc:  # the results stand without their report
            self._logger.error(f'the report could not be written: {exc}\n'
                               f'{traceback.format_exc()}')
            return ''

    def close(self) -> None:
        """Close the recording (the results attached) and the results files. Idempotent."""
        try:
            if self.recorder is not None:
                self._close_recording()
        finally:
            self.recorder = None
            if self.writer is not None:
                self.writer.close()

    def _open_recording(self, run_dir: str, resume: bool) -> Recorder:
        path, k = os.path.join(run_dir, 'recording.mcap'), 1
        while resume and os.path.exists(path):
            k += 1
            path = os.path.join(run_dir, f'recording_{k}.mcap')
        recorder = Recorder(path, self._chunk_size)
        recorder.attach('experiment.yaml', self.file.text.encode(), 'application/yaml')
        recorder.metadata('run', {'experiment_id': self.file.id, 'seed': str(self.file.seed),
                                  'experiment_file': self.file.path, 'run_directory': run_dir,
                                  'resumed': str(bool(resume)), 'node': self._node_name})
        recorder.flush()
        self._topics.start(recorder)
        return recorder

    def _close_recording(self) -> None:
        self._topics.stop(self.recorder)
        try:
            for name in RESULT_FILES:
                path = self.writer.path(name)
                if os.path.exists(path):
                    with open(path, 'rb') as f:
                        self.recorder.attach(name, f.read(), 'application/json'
                                             if name.endswith('.json') else 'text/csv')
        finally:
            self.recorder.close()
