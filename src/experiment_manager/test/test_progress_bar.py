"""The terminal's progress line: redrawn within the terminal's width, a line per 5 % in a log."""

import io
from types import SimpleNamespace

from experiment_manager.commands.progress_bar import ProgressBar


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _progress(done: int, total: int = 46, phase: str = 'sweep: n = 35, iteration 12 of 40'):
    return SimpleNamespace(experiment_id='sweep', iterations_done=done, iterations_total=total,
                           elapsed=12.0 * done, eta=31.0, phase=phase)


def test_an_80_column_terminal_redraws_one_line_that_fits():
    screen = Terminal()
    bar = ProgressBar(screen, columns=80)
    for done in range(47):
        bar.update(_progress(done, phase='feeder: run 3 of 50, a phase far longer than the '
                             'terminal is wide, which the line cuts at its end'))
    bar.close()
    frames = [f for f in screen.getvalue().rstrip('\n').split('\r') if f]
    assert len(frames) >= 47 and screen.getvalue().count('\n') == 1    # redrawn, not scrolled
    assert max(len(f) for f in frames) == 80
    assert frames[-1].startswith('46/46 [########################] 0:09:12 elapsed, eta 0:00:31')


def test_a_log_gets_a_line_per_twentieth_and_per_experiment():
    log = io.StringIO()
    bar = ProgressBar(log)
    for done in range(41):
        bar.update(_progress(done, total=40))
    lines = log.getvalue().splitlines()
    assert len(lines) == 21 and lines[-1].startswith('40/40  0:08:00 elapsed, eta 0:00:31')


def test_an_adaptive_run_says_its_estimate_is_of_the_most_it_may_take():
    log = io.StringIO()
    bar = ProgressBar(log)
    bar.at_most = True
    bar.update(_progress(3))
    assert log.getvalue().startswith('3/46  0:00:36 elapsed, eta at most 0:00:31')
