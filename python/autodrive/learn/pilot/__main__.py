"""python -m autodrive.learn.pilot: see cli.py."""

import sys

from autodrive.learn.pilot.cli import main

sys.exit(main())
