"""What every output records beside itself: versions, hashes, and atomic writes of JSON (and of figures)."""
from __future__ import annotations

import os
import platform
import time
from importlib import metadata

from pddl_export.files import (atomic_write_bytes, atomic_write_json, atomic_write_text,  # noqa: F401 (re-exported)
                                sha256_bytes, sha256_file)

_PACKAGES = ("symlearn", "numpy", "pybullet", "torch", "unified-planning")


def atomic_write_png(fig, path, dpi: int) -> None:
    """A matplotlib figure as PNG, written through the one atomic writer (no stray temp file on failure)."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, dpi=dpi, format="png")
    atomic_write_bytes(path, buf.getvalue())


def versions() -> dict[str, str]:
    """Python and the versions of the packages the toolkit's results depend on."""
    out = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def bench_context() -> dict:
    """Where and when a bench script ran, and with what: the machine, its CPU count, today's date and versions()."""
    return {"machine": f"{platform.machine()}, {platform.processor() or 'cpu'}", "cpus": os.cpu_count(),
            "date": time.strftime("%Y-%m-%d"), "versions": versions()}
