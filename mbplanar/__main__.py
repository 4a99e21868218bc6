"""``python -m mbplanar``: the command line as a process of its own (`mbplanar.cli.run`)."""

import sys

from .cli import run

sys.exit(run())
