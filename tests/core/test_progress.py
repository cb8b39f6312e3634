"""The CLI's live progress line: what it says, and how it is written to a terminal and to a log."""
import io

import pytest

from drt_engine.headless.progress import ProgressDisplay, progress_text, time_left
from drt_engine.core.render.render import ProgressUpdate


class Terminal(io.StringIO):
    def isatty(self):
        return True


def update(done=16, total=64, elapsed=4.0, error=1e-3, fraction=0.25):
    return ProgressUpdate(fraction, done, total, elapsed, None, error)


def test_time_left_is_the_soonest_end():
    # a quarter done in 4 s: 12 s more to the cap
    assert time_left(0.25, 4.0, 1e-3, 0.0, 0.0) == (12.0, "the sample cap")
    assert time_left(0.25, 4.0, 1e-3, 10.0, 0.0) == (6.0, "the time limit")
    # relMSE 1e-3 after 4 s falls to 5e-4 after 8 s: 4 s more
    assert time_left(0.25, 4.0, 1e-3, 0.0, 5e-4) == (4.0, "the target error")
    assert time_left(0.0, 0.0, float("inf"), 0.0, 5e-4) is None


def test_progress_text_says_samples_error_time_and_time_left():
    text = progress_text(update(), time_limit=10.0)
    assert text == "Sample 16/64 | est. error 3.2% | 4.0 s | ~6 s left to the time limit"
    assert "est. error ?" in progress_text(update(error=float("inf"), fraction=0.0, elapsed=0.0))


def test_a_terminal_gets_one_line_rewritten_in_place(monkeypatch):
    stream = Terminal()
    display = ProgressDisplay(stream)
    clock = iter([0.0, 1.0, 2.0])
    monkeypatch.setattr("drt_engine.headless.progress.time.monotonic", lambda: next(clock))
    display(update(done=1000, total=4096, fraction=0.2))
    display(update(done=2, total=4096, fraction=0.5))
    display.close()
    text = stream.getvalue()
    assert text.count("\n") == 1 and text.endswith("\n")
    lines = text[:-1].split("\r")[1:]
    assert [line.split(" |")[0] for line in lines] == ["DRT: Sample 1000/4096", "DRT: Sample 2/4096"]
    assert len(lines[1]) == len(lines[0])  # the shorter line blanks the rest of the longer one


@pytest.mark.parametrize("times, lines", [([0.0, 1.0, 11.0], 2), ([0.0, 1.0, 2.0], 1)])
def test_a_log_gets_plain_lines_every_interval(monkeypatch, times, lines):
    stream = io.StringIO()
    display = ProgressDisplay(stream)
    clock = iter(times)
    monkeypatch.setattr("drt_engine.headless.progress.time.monotonic", lambda: next(clock))
    for _ in times:
        display(update())
    display.close()
    text = stream.getvalue()
    assert "\r" not in text and text.count("\n") == lines
    assert all(line.startswith("DRT: Sample 16/64 | est. error") for line in text.splitlines())
