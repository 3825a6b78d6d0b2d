"""Exceptions that the command line turns into one clear line and an exit code.

Exit codes (see ``suspsim.cli``): 0 ok, 1 user or input error (:class:`InputError`),
2 numerical failure (:class:`NumericalError`).
"""
from __future__ import annotations

from os import PathLike


class SuspsimError(Exception):
    """Base class of every error suspsim raises on purpose."""


class InputError(SuspsimError):
    """A file, scene or argument the user gave is unusable.

    The message names the file, where in it (line, sheet or key) and the problem, e.g.
    ``data/x/matrix.csv:14: shear rate 'abc' is not a number``.

    Parameters
    ----------
    source : path or str
        The file (or other input) at fault.
    problem : str
        What is wrong, phrased so the user knows what to change.
    line : int, optional
        1-based line number in a text file.
    sheet : str, optional
        Worksheet name in a spreadsheet.
    key : str, optional
        Dotted key in a configuration or scene file.
    """

    def __init__(self, source: str | PathLike, problem: str, *, line: int | None = None,
                 sheet: str | None = None, key: str | None = None):
        self.source = str(source)
        self.problem = problem
        self.line = line
        self.sheet = sheet
        self.key = key
        where = self.source
        if line is not None:
            where += f":{line}"
        if sheet is not None:
            where += f" [sheet {sheet!r}]"
        if key is not None:
            where += f" [key {key!r}]"
        super().__init__(f"{where}: {problem}")


class NumericalError(SuspsimError):
    """A computation failed numerically (no convergence, blow-up); the message says what to change."""
