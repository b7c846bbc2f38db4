"""The run report: one HTML page and one Markdown file built from a run's own outputs (see build.py)."""
