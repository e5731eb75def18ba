"""Results files of a run, written as iterations finish.

A run directory holds:
- `experiment.yaml`: the experiment file as it was read (and a mesh part's file beside it,
  where it names it: `keep_part_file`);
- `iterations.csv`: one row per iteration (rows.ITERATION_COLUMNS);
- `checks.csv`: one row per validity check (rows.CHECK_COLUMNS);
- `parts.csv`: one row per part per check, with its pose and stage (rows.PART_COLUMNS);
- `picks.csv`: one row per picked part, with the gripper pose (rows.PICK_COLUMNS);
- `summary.json`: the metrics, rewritten (atomically) after each experiment.

An iteration's rows are appended and flushed together, `iterations.csv` last: a run that stops
keeps every finished iteration, and an `iterations.csv` row means the iteration is whole. On
resume, rows of unfinished iterations are dropped from the other files and the finished ones
are skipped. Floats are written with repr(), which reads back to the same float.
"""

from collections.abc import Callable
import csv
import os
import shutil
import tempfile

from pick_common.errors import InvalidArgument

from .rows import FILES, KEY, parse_row, Record
from .summary import Summary

UMASK = os.umask(0o022)
os.umask(UMASK)
def keep_part_file(mesh_path: str, experiment_path: str, directory: str) -> str:
    """Copy a mesh part's file (`mesh_path`, absolute) into the run `directory` where its
    experiment.yaml names it (relative to `experiment_path`, the file read), so that the
    directory reads on its own: `run --resume`, the pictures, a review elsewhere. Returns the
    copy's path; '' when the file names it by an absolute path or from above its own
    directory (`../`), where the name reads as it is."""
    if not mesh_path or not experiment_path:
        return ''
    relative = os.path.relpath(mesh_path, os.path.dirname(experiment_path))
    if relative.startswith(os.pardir):
        return ''
    target = os.path.join(directory, relative)
    os.makedirs(os.path.dirname(target), exist_ok=True)
    shutil.copyfile(mesh_path, target)
    return target


def write_atomic(path: str, text: str) -> None:
    """Write a text file atomically (a reader never sees half of it), with the mode open()
    would give it."""
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path) or '.',
                               prefix=f'.{os.path.basename(path)}.')
    with os.fdopen(fd, 'w', encoding='utf-8') as f:
        f.write(text)
    os.chmod(tmp, 0o666 & ~UMASK)   # as open() would create it, not mkstemp's 0600
    os.replace(tmp, path)


def write_summary(directory: str, summary: Summary) -> None:
    """A run directory's summary.json (Summary.json_text): the model checked every record as
    it was made, so a summary that breaks the published schema never comes this far."""
    write_atomic(os.path.join(directory, 'summary.json'), summary.json_text())


def read_csv(path: str) -> list[dict]:
    """The rows of a results file, typed."""
    return [parse_row(r) for r in read_text_rows(path)]


def read_text_rows(path: str, drop: tuple[str, ...] = ()) -> list[dict]:
    """The rows of a results file as written (strings), without the `drop` columns: what two
    runs are compared on (wall times differ from run to run)."""
    with open(path, newline='', encoding='utf-8') as f:
        return [{k: v for k, v in r.items() if k not in drop} for r in csv.DictReader(f)]


def _key(row: dict) -> tuple:
    return row['experiment'], row['group'], row['iteration']


def _blocks(path: str) -> tuple[bytes, list[tuple[tuple, int, int]]]:
    """A results file's header line and its blocks of rows, one per run of rows of one
    iteration, as (iteration key, start, end) byte offsets, in file order. The file is read a
    line at a time (millions of rows are never held in memory: parsing every row to resume the
    paper's PTH1 took 6.9 GB and 63 s). A torn last line (no line end: the writer was killed
    mid-row) is left out, whatever its key reads as; a torn header gives b'' and no blocks."""
    blocks: list[tuple[tuple, int, int]] = []
    with open(path, 'rb') as f:
        header = f.readline()
        if not header.endswith(b'\n'):
            return b'', blocks
        columns = header.decode().rstrip('\r\n').split(',')
        at = [columns.index(k) for k in KEY]
        start = offset = f.tell()
        key = None
        for line in iter(f.readline, b''):
            if not line.endswith(b'\n'):
                break
            fields = line.split(b',', max(at) + 1)
            here = fields[at[0]].decode(), int(fields[at[1]]), int(fields[at[2]])
            if here != key:
                if key is not None:
                    blocks.append((key, start, offset))
                start, key = offset, here
            offset += len(line)
        if key is not None:
            blocks.append((key, start, offset))
    return header, blocks


class ResultsWriter:
    """The results of one run directory. `resume`: keep the finished iterations found there."""

    def __init__(self, directory: str, experiment_text: str, resume: bool = False) -> None:
        self.directory = directory
        # The rows the metrics read (parts.csv, by far the largest, is never held).
        self._rows: dict[str, list[dict]] = {'iterations': [], 'checks': [], 'picks': []}
        try:
            os.makedirs(directory, exist_ok=True)
            probe = tempfile.NamedTemporaryFile(dir=directory, prefix='.write-test-')
            probe.close()
        except OSError as exc:
            raise InvalidArgument('output_dir', directory,
                                  f'cannot be written: {exc.strerror or exc}') from None
        existing = os.path.exists(self.path('iterations'))
        if existing and not resume:
            raise InvalidArgument('output_dir', directory, 'already holds results: resume '
                                  'the run there, or choose another directory')
        if resume and not existing:
            raise InvalidArgument('output_dir', directory, 'holds no run to resume '
                                  '(no iterations.csv)')
        if resume:
            self._resume(experiment_text)
        else:
            self._write_text('experiment.yaml', experiment_text)
        self._files = {}
        self._writers = {}
        for name in FILES:
            self._open(name)
        self._done = {_key(r) for r in self._rows['iterations']}

    def _open(self, name: str) -> None:
        new = not os.path.exists(self.path(name))
        f = open(self.path(name), 'a', newline='', encoding='utf-8')
        self._files[name] = f
        self._writers[name] = csv.DictWriter(f, FILES[name], extrasaction='raise')
        if new:
            self._writers[name].writeheader()
            f.flush()

    def path(self, name: str) -> str:
        return os.path.join(self.directory, name if '.' in name else f'{name}.csv')

    def _write_text(self, name: str, text: str) -> None:
        write_atomic(self.path(name), text)

    def _resume(self, experiment_text: str) -> None:
        try:
            with open(self.path('experiment.yaml'), encoding='utf-8') as f:
                before = f.read()
        except OSError:
            before = None
        if before != experiment_text:
            raise InvalidArgument('experiment_file', self.path('experiment.yaml'),
                                  'differs from the file of the run being resumed: results '
                                  'would mix two experiments')
        scans = {name: _blocks(self.path(name)) for name in FILES
                 if os.path.exists(self.path(name))}
        done = {key for key, _, _ in scans['iterations'][1]}   # whole rows
        for name, (header, blocks) in scans.items():   # without the iterations in flight
            if not header:      # cut inside its header, so no rows: _open writes it anew
                os.remove(self.path(name))
                continue
            columns = header.decode().rstrip('\r\n').split(',')
            if columns != list(FILES[name]):
                gone = [c for c in columns if c not in FILES[name]]
                new = [c for c in FILES[name] if c not in columns]
                raise InvalidArgument('resume', self.path(name),
                                      f'has the columns of another version (missing: '
                                      f'{", ".join(new) or "none"}; unknown: '
                                      f'{", ".join(gone) or "none"}): start a new run')
            self._write_blocks(name, header, [b for b in blocks if b[0] in done])
            if name in self._rows:
                self._rows[name] = read_csv(self.path(name))

    # ------------------------------------------------------------------------- Sink
    def is_done(self, experiment_id: str, group: int, iteration: int) -> bool:
        return (experiment_id, group, iteration) in self._done

    def write(self, record: Record) -> None:
        for name, rows in (('parts', record.parts), ('checks', record.checks),
                           ('picks', record.picks), ('iterations', [record.iteration])):
            self._writers[name].writerows(rows)
            self._files[name].flush()
        self._rows['iterations'].append(record.iteration)
        self._rows['checks'] += record.checks
        self._rows['picks'] += record.picks
        self._done.add(_key(record.iteration))

    def reorder(self, rank: dict[tuple, tuple]) -> None:
        """Put the rows in the order of `rank` (iteration key -> its place in the plan, any
        sortable value); keys it lacks go last, in the order they have. Several workers finish
        iterations out of order; the files of a run are then the same whoever ran what. A
        no-op when the rows are in order already."""
        def position(key: tuple, index: int) -> tuple:
            return (0, rank[key]) if key in rank else (1, index)

        keys = {_key(r): i for i, r in enumerate(self._rows['iterations'])}
        order = [position(k, i) for k, i in keys.items()]
        if order == sorted(order):
            return
        for name in FILES:
            self._files[name].close()
            self._move_blocks(name, position)
            self._open(name)
        for name, rows in self._rows.items():
            self._rows[name] = sorted(rows, key=lambda r: position(_key(r), keys[_key(r)]))

    def _move_blocks(self, name: str, position: Callable[[tuple, int], tuple]) -> None:
        """Rewrite a results file with its blocks of rows, one block per iteration as write()
        appended it, sorted by position(key, block index)."""
        header, blocks = _blocks(self.path(name))
        order = sorted(range(len(blocks)), key=lambda i: position(blocks[i][0], i))
        self._write_blocks(name, header, [blocks[i] for i in order])

    def _write_blocks(self, name: str, header: bytes, blocks: list[tuple[tuple, int, int]]
                      ) -> None:
        """Replace a results file atomically with its header and `blocks` (of _blocks), in
        the order given, copied byte for byte."""
        fd, tmp = tempfile.mkstemp(dir=self.directory, prefix=f'.{name}.')
        with open(self.path(name), 'rb') as f, os.fdopen(fd, 'wb') as out:
            out.write(header)
            for _, begin, end in blocks:
                f.seek(begin)
                out.write(f.read(end - begin))
        os.chmod(tmp, 0o666 & ~UMASK)   # as open() would create it, not mkstemp's 0600
        os.replace(tmp, self.path(name))

    def iterations(self, experiment_id: str) -> list[dict]:
        return [r for r in self._rows['iterations'] if r['experiment'] == experiment_id]

    def picks(self, experiment_id: str) -> list[dict]:
        return [r for r in self._rows['picks'] if r['experiment'] == experiment_id]

    def checks(self, experiment_id: str) -> list[dict]:
        return [r for r in self._rows['checks'] if r['experiment'] == experiment_id]

    def write_summary(self, summary: Summary) -> None:
        write_summary(self.directory, summary)

    def close(self) -> None:
        for f in self._files.values():
            f.close()

    def __enter__(self) -> 'ResultsWriter':
        return self

    def __exit__(self, *exc) -> None:
        self.close()
