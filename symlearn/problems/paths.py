"""Names that become paths: the safe-name rule and `path_under`, which refuses paths escaping their folder.

Every name read from a file (a problem's name) or built from one must pass `check_safe_name`
before it becomes part of a path, and every such path is built with `path_under(base, *parts)`.

    >>> path_under(Path("/runs/r/pddl/problems"), "problem_0000")
    PosixPath('/runs/r/pddl/problems/problem_0000')
    >>> path_under(Path("/runs/r"), "../x")
    Traceback (most recent call last):
    ...
    ValueError: path '../x' escapes /runs/r
"""
from __future__ import annotations

import re
from pathlib import Path

SAFE_NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]{0,99}")
SAFE_NAME_RULE = "1-100 characters of A-Z a-z 0-9 . _ -, not starting with '.'"


def is_safe_name(name: object) -> bool:
    """Whether `name` may be used as one path component (SAFE_NAME_RULE)."""
    return isinstance(name, str) and SAFE_NAME.fullmatch(name) is not None


def check_safe_name(name: object, what: str) -> str:
    """`name` itself, or a one-line ValueError naming `what` and the rule."""
    if not is_safe_name(name):
        raise ValueError(f"{what}: name {str(name)[:120]!r} is not a safe name ({SAFE_NAME_RULE})")
    return name  # type: ignore[return-value]


def path_under(base: Path, *parts: str) -> Path:
    """base/parts..., refused with a one-line ValueError when it resolves outside base (.., absolute parts, links)."""
    root = Path(base).resolve()
    joined = Path(base).joinpath(*parts)
    if not joined.resolve().is_relative_to(root) or joined.resolve() == root and parts:
        raise ValueError(f"path {str(Path(*parts)) if parts else ''!r} escapes {base}")
    return joined
