#!/bin/sh
# No function over MAX lines in the simulator's C sources (issue 42: units with one job).
# Lengths come from universal-ctags (Debian's universal-ctags): the line of a function's
# signature to the line of its closing brace. Usage: check_function_lengths.sh DIR [MAX]
set -eu
dir=$1
max=${2:-120}
if ! ctags --version 2>/dev/null | grep -q "Universal Ctags"; then
  echo "universal-ctags is not installed (tools/debian-packages.txt)" >&2
  exit 77
fi
long=$(find "$dir" -name '*.c' -print | sort |
  xargs ctags -x --_xformat='%{line} %{end} %N %F' --kinds-C=f --fields=+ne --languages=C |
  awk -v max="$max" '$2 == "" { print "no end line for " $3 " in " $4; next }
                     { n = $2 - $1 + 1; if (n > max) print n " lines: " $3 " (" $4 ":" $1 ")" }')
if [ -n "$long" ]; then
  echo "functions over $max lines in $dir:" >&2
  echo "$long" >&2
  exit 1
fi
echo "no function over $max lines in $dir"
