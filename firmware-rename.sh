#!/usr/bin/env bash
# Issue 42: applies firmware-rename.sed (the firmware's new paths and spelled-out names) to every
# tracked text file that names an old one. Run from the repository root after merging:
#   ./firmware-rename.sh            rewrite in place (then review `git diff --stat`)
#   ./firmware-rename.sh --list     only list the files that would be rewritten
# Idempotent: a second run changes nothing.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
script="$PWD/firmware-rename.sed"

# Any old name or path the sed rewrites (a superset is fine: sed leaves other files as they are).
old='firmware/nano/(lib|src)\b|\b(fs|wspd|act|enc|batt|proto|nigel|nigel_core|nigel_hal|fw)_[A-Za-z0-9_]|\b(FS|WSPD|ACT|ENC|BATT|PROTO|NIGEL|FW)_[A-Z0-9_]|\b(fs|wspd|act|enc|batt|proto|nigel_core|nigel_hal)\.[ch]\b|\bnano_(proto|enc)\b|(\.|->)(fs|act|batt|wspd)\b|\bstruct (fs|wspd|act|enc|batt|nigel)\b|\b(fs|wspd|act|enc|batt|proto|nigel)/'

files=$(git grep -lIE "$old" -- . ':!firmware-rename.sed' ':!firmware-rename.sh' || true)
if [ "${1:-}" = "--list" ]; then
  printf '%s\n' $files
  exit 0
fi
[ -n "$files" ] || { echo "firmware-rename: nothing to rewrite"; exit 0; }
printf '%s\n' $files | xargs sed -i -E -f "$script"
# Longer names move line ends: reformat the rewritten files with the project's formatters.
changed=$(git diff --name-only -- $files)
cfiles=$(printf '%s\n' $changed | grep -E '\.(c|h|cpp|hpp)$' | grep -v '/fixtures/' || true)
pyfiles=$(printf '%s\n' $changed | grep -E '\.py$' || true)
[ -z "$cfiles" ] || clang-format-14 -i $cfiles
[ -z "$pyfiles" ] || black --quiet $pyfiles
echo "firmware-rename: $(printf '%s\n' $changed | grep -c . || true) file(s) rewritten; see git diff --stat"
