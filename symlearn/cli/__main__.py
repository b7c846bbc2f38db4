"""`python -m symlearn.cli ARGS` runs the `symlearn` command, e.g. under torchrun on each node (docs/SCALING.md)."""
import sys

from symlearn.cli.main import main

if __name__ == "__main__":
    sys.exit(main())
