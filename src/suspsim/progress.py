"""Progress of a long run: a carriage-return line on a terminal, a log line otherwise.

On a terminal (``stream.isatty()``) one status line on ``stream`` is rewritten at most every
:data:`TTY_REFRESH_S` seconds: ``strain 3.20/10 (32 %)  1.2e+04 steps/s  ETA 0:05:13``.
Elsewhere (batch jobs, redirected stderr) the same text goes to the log, at INFO level, each
time another :data:`LOG_FRACTION` of the run is done or :data:`LOG_INTERVAL_S` seconds have
passed, whichever comes first. Rates and ETA count only the steps of this process (a resumed
run does not inherit the speed of an earlier segment).
"""
from __future__ import annotations

import logging
import sys
import time
from typing import Callable, TextIO

log = logging.getLogger(__name__)

#: Seconds between rewrites of the terminal line.
TTY_REFRESH_S = 0.2
#: Fraction of the run between log lines.
LOG_FRACTION = 0.1
#: Longest wall time between log lines [s].
LOG_INTERVAL_S = 30.0


def format_duration(seconds: float) -> str:
    """``H:MM:SS`` for a duration in seconds; ``?`` when unknown."""
    if not seconds >= 0 or seconds == float("inf"):
        return "?"
    whole = int(round(seconds))
    return f"{whole // 3600}:{whole % 3600 // 60:02d}:{whole % 60:02d}"


class ProgressReporter:
    """Report how far a run is: ``begin``, then ``update`` after each piece of work, ``close``.

    Parameters
    ----------
    stream : where the terminal line goes (default ``sys.stderr``).
    tty : force terminal (True) or log (False) mode; default ``stream.isatty()``.
    clock : wall-clock function in seconds (injectable for tests).
    """

    def __init__(self, *, stream: TextIO | None = None, tty: bool | None = None,
                 clock: Callable[[], float] = time.monotonic):
        self.stream = sys.stderr if stream is None else stream
        self.tty = self.stream.isatty() if tty is None else bool(tty)
        self._clock = clock
        self.begin(1.0)

    def begin(self, total: float, unit: str = "strain") -> None:
        """Start reporting a run of length ``total`` in ``unit`` (strain [1] or time [tau])."""
        self.total = float(total)
        self.unit = unit
        self._start: tuple[float, int] | None = None
        self._last_write = -float("inf")
        self._last_fraction = -float("inf")
        self._last_steps: int | None = None
        self._width = 0

    def update(self, done: float, steps: int, total_steps: int, *, force: bool = False) -> None:
        """Report ``done`` (in the run's unit) after ``steps`` of ``total_steps`` steps.

        The first call only starts the clock (and reports, so a resumed run shows where it is).
        ``force`` writes regardless of the cadence, unless this step was reported already.
        """
        if force and steps == self._last_steps:
            return
        now = self._clock()
        if self._start is None:
            self._start = (now, steps)
        fraction = done / self.total if self.total > 0 else 1.0
        if self.tty:
            if force or now - self._last_write >= TTY_REFRESH_S:
                self._write_line(self.describe(done, steps, total_steps, now))
                self._last_write, self._last_steps = now, steps
        elif (force or fraction - self._last_fraction >= LOG_FRACTION - 1e-12
              or now - self._last_write >= LOG_INTERVAL_S):
            log.info("%s", self.describe(done, steps, total_steps, now))
            self._last_write, self._last_fraction, self._last_steps = now, fraction, steps

    def describe(self, done: float, steps: int, total_steps: int, now: float) -> str:
        """The status text: progress in the run's unit, steps per second, ETA."""
        start_time, start_steps = self._start if self._start is not None else (now, steps)
        elapsed = now - start_time
        rate = (steps - start_steps) / elapsed if elapsed > 0 and steps > start_steps else 0.0
        eta = (total_steps - steps) / rate if rate > 0 else float("nan")
        percent = 100.0 * done / self.total if self.total > 0 else 100.0
        return (f"{self.unit} {done:.4g}/{self.total:.4g} ({percent:.0f} %)  "
                f"{rate:.3g} steps/s  ETA {format_duration(eta)}")

    def close(self) -> None:
        """End the terminal line so later messages start on a fresh one."""
        if self.tty and self._width:
            self.stream.write("\n")
            self.stream.flush()
            self._width = 0

    def _write_line(self, text: str) -> None:
        # Pad with spaces to erase the tail of a longer previous line (no terminal escapes).
        self.stream.write("\r" + text.ljust(self._width))
        self.stream.flush()
        self._width = len(text)


class NullProgress(ProgressReporter):
    """A reporter that reports nothing (for library use and quiet runs)."""

    def update(self, done: float, steps: int, total_steps: int, *, force: bool = False) -> None:
        return None
