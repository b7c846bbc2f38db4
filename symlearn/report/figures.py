"""Drawing the report's plots with matplotlib (Agg backend: no display needed), as PNG bytes."""
from __future__ import annotations

import io

from symlearn.report.model import Plot


def plot_png(plot: Plot, width_in: float = 5.0, height_in: float = 3.2, dpi: int = 100) -> bytes:
    """One Plot drawn as a PNG: a line with markers per series, legend, labelled axes."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure  # a bare Figure: no pyplot state, safe in any thread

    fig = Figure(figsize=(width_in, height_in), dpi=dpi)
    ax = fig.add_subplot(1, 1, 1)
    for label, (x, y) in plot.series.items():
        ax.plot(x, y, marker="o", markersize=3, label=label)
    if plot.log_y:
        ax.set_yscale("log")
    if plot.xlabel == "epoch":
        from matplotlib.ticker import MaxNLocator

        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_title(plot.title)
    ax.set_xlabel(plot.xlabel)
    ax.set_ylabel(plot.ylabel)
    ax.grid(alpha=0.3)
    if plot.series:
        ax.legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()
