"""Argument types shared by the `symlearn` sub-commands (argparse `type=` callables)."""
from __future__ import annotations

import argparse


def int_range(text: str) -> tuple[int, int]:
    """'1-3' -> (1, 3); '4' -> (4, 4); anything else is an argparse error naming the text."""
    try:
        lo, _, hi = text.partition("-")
        lo_i, hi_i = int(lo), int(hi or lo)
    except ValueError:
        raise argparse.ArgumentTypeError(f"range {text!r} must look like 1-3 or 4") from None
    if lo_i > hi_i:
        raise argparse.ArgumentTypeError(f"range {text!r} is empty")
    return lo_i, hi_i


def planner_list(text: str) -> list[str]:
    """'astar, astar-ucs' -> ['astar', 'astar-ucs']; an empty list is an argparse error."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise argparse.ArgumentTypeError("give at least one planner, e.g. astar,astar-ucs")
    return names
