"""python -m autodrive_tools.pilot: see cli.py."""

import sys

from .cli import main

sys.exit(main())
