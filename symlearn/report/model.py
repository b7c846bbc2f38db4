"""The report as plain data: sections of tables, marks against the paper, plots and images.

Gathering (symlearn.report.gather) fills these from a run's JSON outputs; rendering
(symlearn.report.render) turns them into HTML or Markdown; figures (symlearn.report.figures)
draws the plots. Nothing here computes anything.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

OK, NOT_RUN, INVALID = "ok", "not run", "invalid"


@dataclass(frozen=True)
class Mark:
    """One number the paper reports, ours beside it, and whether ours meets the stated criterion."""

    claim: str  # e.g. "effect MAE x (mm)"
    ours: float | str | None
    paper: float | str
    criterion: str  # e.g. "below the paper's"
    met: bool | None  # None: ours unknown
    invalid: bool = False  # ours is impossible, or its file was refused: never counted as met
    valid: tuple[float, float] = (-math.inf, math.inf)  # the values ours can take (an error is >= 0)

    @property
    def verdict(self) -> str:
        """'invalid' (refused, or a number outside `valid`), else 'met', 'not met', or 'not run'."""
        number = isinstance(self.ours, (int, float)) and not isinstance(self.ours, bool)
        if self.invalid or (number and not self.valid[0] <= self.ours <= self.valid[1]):
            return INVALID
        return NOT_RUN if self.met is None else "met" if self.met else "not met"


@dataclass(frozen=True)
class Table:
    """A caption, a header row and rows of cells (numbers stay numbers until rendered)."""

    caption: str
    header: tuple[str, ...]
    rows: tuple[tuple, ...]
    key: str = ""  # names the table in HTML (data-table attribute) for readers and tests


@dataclass(frozen=True)
class Plot:
    """Line series to draw: {label: (x values, y values)} on shared axes."""

    name: str  # file stem
    title: str
    xlabel: str
    ylabel: str
    series: dict
    log_y: bool = False


@dataclass(frozen=True)
class Image:
    """A picture file the run already holds (PNG), shown as is."""

    name: str
    caption: str
    path: Path


@dataclass
class Section:
    """One part of the report; status NOT_RUN says why in `note` and holds nothing else."""

    key: str
    title: str
    status: str = OK
    note: str = ""
    text: list[str] = field(default_factory=list)
    marks: list[Mark] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    plots: list[Plot] = field(default_factory=list)
    images: list[Image] = field(default_factory=list)


@dataclass
class Report:
    """Every section, in order, for one run."""

    run: Path
    sections: list[Section]

    def marks(self) -> list[Mark]:
        """Every mark of every section, in order (the scorecard)."""
        return [m for s in self.sections for m in s.marks]


def not_run(key: str, title: str, why: str, marks: list[Mark] | None = None) -> Section:
    """A section whose inputs are missing; `marks` (invalid ones, for a file refused) still reach the scorecard."""
    return Section(key, title, status=NOT_RUN, note=why, marks=list(marks or []))
