"""The CLI's live progress: what Blender's status bar shows, on the terminal while the render runs.

On a terminal one line is rewritten in place; otherwise (a log file, a pipe) a plain line
is written every PLAIN_INTERVAL seconds, so logs stay readable and small.
"""
from __future__ import annotations

import math
import time

from ..core.render import report

TERMINAL_INTERVAL = 0.2
PLAIN_INTERVAL = 10.0
"""Seconds between two lines when the output is not a terminal."""


def time_left(fraction: float, elapsed: float, relmse: float, time_limit: float, target_error: float):
    """(seconds, what ends the render then) for the soonest of the sample cap, the time limit and
    the target error; None while unknown.

    To the cap the rate so far holds; to the target error the estimated relMSE falls as one
    over the time spent (as it does for a fixed sampling rate).
    """
    ends = []
    if 0 < fraction < 1 and elapsed > 0:
        ends.append((elapsed * (1 - fraction) / fraction, "the sample cap"))
    if time_limit > 0:
        ends.append((max(time_limit - elapsed, 0.0), "the time limit"))
    if target_error > 0 and math.isfinite(relmse) and relmse > 0 and elapsed > 0:
        ends.append((elapsed * max(relmse / target_error - 1.0, 0.0), "the target error"))
    return min(ends) if ends else None


def progress_text(update, time_limit: float = 0.0, target_error: float = 0.0) -> str:
    """'Sample 12/64 | est. error 0.8% | 3.2 s | ~9 s left to the sample cap' from a core ProgressUpdate."""
    text = (f"Sample {update.samples_done}/{update.samples_total} | est. error "
            f"{report.relative_error_text(update.error)} | {update.elapsed:.1f} s")
    left = time_left(update.fraction, update.elapsed, update.error, time_limit, target_error)
    if left is not None:
        text += f" | ~{left[0]:.0f} s left to {left[1]}"
    return text


class ProgressDisplay:
    """Called with each core ProgressUpdate; writes to ``stream`` at most every interval."""

    def __init__(self, stream, time_limit: float = 0.0, target_error: float = 0.0):
        self.stream = stream
        self.terminal = stream.isatty()
        self.interval = TERMINAL_INTERVAL if self.terminal else PLAIN_INTERVAL
        self.time_limit, self.target_error = time_limit, target_error
        self._last = -math.inf
        self._width = 0  # of the line on screen, to blank what a shorter one leaves

    def __call__(self, update) -> None:
        now = time.monotonic()
        if now - self._last < self.interval:
            return
        self._last = now
        text = "DRT: " + progress_text(update, self.time_limit, self.target_error)
        if self.terminal:
            self.stream.write("\r" + text.ljust(self._width))
            self._width = len(text)
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def close(self) -> None:
        """End the line rewritten in place, so what follows starts on its own."""
        if self.terminal and self._width:
            self.stream.write("\n")
            self.stream.flush()
        self._width = 0
