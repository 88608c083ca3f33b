"""``python -m grazing``: the command line."""

from grazing.cli import main
from grazing.cli.quick_exit import quick_exit

quick_exit(main())
