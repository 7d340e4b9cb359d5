"""python -m autodrive_tools.marl: tools/marl."""

from .cli import main

raise SystemExit(main())
