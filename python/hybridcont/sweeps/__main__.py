"""`python -m hybridcont.sweeps`: what `hybridcont sweep` runs."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
