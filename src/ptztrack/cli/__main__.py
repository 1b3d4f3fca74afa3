"""``python -m ptztrack.cli``: the ``ptztrack`` command."""

import sys

from ptztrack.cli import main

if __name__ == "__main__":
    sys.exit(main())
