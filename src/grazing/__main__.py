"""``python -m grazing``: the command line."""

import sys

from grazing.cli import main

sys.exit(main())
