"""``python -m grazing.cli``: the ``grazing`` command."""

import sys

from grazing.cli import main

if __name__ == "__main__":
    sys.exit(main())
