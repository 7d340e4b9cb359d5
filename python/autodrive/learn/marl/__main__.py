"""python -m autodrive.learn.marl: tools/marl."""

from autodrive.learn.marl.cli import main

raise SystemExit(main())
