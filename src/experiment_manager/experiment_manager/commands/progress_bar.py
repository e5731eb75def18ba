"""The progress bar of `run`: one line on a terminal, a line per 5 % in a log."""

import sys

from tqdm import tqdm


class ProgressBar:
    """The run's progress on `stream`: on a terminal, one tqdm line redrawn within the
    terminal's width (`columns`, or the terminal's own as it is resized), the phase cut at its
    end; otherwise (a log), a line per 5 % and per experiment."""

    def __init__(self, stream=sys.stderr, columns: int | None = None) -> None:
        self.stream, self.columns = stream, columns
        self.tty = stream.isatty()
        # an adaptive run's estimate is of the most it may take (running/estimate.py): said so
        self.at_most = False
        self._bar: tqdm | None = None
        self._last = (None, -1)

    @staticmethod
    def _clock(seconds: float) -> str:
        s = int(seconds)
        return f'{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}'

    def update(self, p) -> None:
        eta = (('at most ' if self.at_most else '') + self._clock(p.eta)) if p.eta else '?'
        status = f'{self._clock(p.elapsed)} elapsed, eta {eta}  {p.phase}'
        if not self.tty:
            fraction = p.iterations_done / p.iterations_total if p.iterations_total else 0.0
            key = (p.experiment_id, int(fraction * 20))
            if key != self._last:
                self._last = key
                self.stream.write(f'{p.iterations_done}/{p.iterations_total}  {status}\n')
                self.stream.flush()
            return
        if self._bar is None:
            self._bar = tqdm(total=p.iterations_total, file=self.stream, ncols=self.columns,
                             dynamic_ncols=self.columns is None, ascii=' #', mininterval=0,
                             bar_format='{n_fmt}/{total_fmt} [{bar:24}] {desc}')
        self._bar.total, self._bar.n = p.iterations_total, p.iterations_done
        self._bar.set_description_str(status, refresh=False)
        self._bar.refresh()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
