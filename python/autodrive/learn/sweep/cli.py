"""tools/sweep: many independent simulated jobs on Ray (embedded and local by default,
--address HOST:PORT joins a cluster, --serial runs them here one after the other).

Subcommands:
  parking   the HIL parking demo over seeds and slots (autodrive.learn.sweep.parking)
  eval      evaluation episodes of a policy, one per seed (autodrive.learn.sweep.episodes)
  rollouts  rollouts of a training run, STEPS transitions per seed (autodrive.learn.sweep.episodes)

tools/sweep SUBCOMMAND --help for the options. Progress on stderr; the last stdout line is the
result as one JSON object."""

from __future__ import annotations

import sys

from autodrive.learn.sweep import parking as sweep, episodes as sweep_learn

SUBCOMMANDS = ("parking", "eval", "rollouts")


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if argv else 2
    cmd, rest = argv[0], argv[1:]
    if cmd == "parking":
        return sweep.main(rest, "tools/sweep parking")
    if cmd in ("eval", "rollouts"):
        return sweep_learn.main(cmd, rest)
    print(
        f"tools/sweep: unknown subcommand '{cmd}' (one of {', '.join(SUBCOMMANDS)})",
        file=sys.stderr,
    )
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
