#!/bin/sh
# run_json.sh REGEX PROGRAM [ARGS...]: runs PROGRAM and fails on a non-zero exit code, on a
# sanitizer report in its output, or when its last stdout line does not match REGEX (grep -E).
# (ctest's PASS_REGULAR_EXPRESSION alone ignores the exit code.)
re="$1"
shift
err="$(mktemp)"
out="$("$@" 2>"$err")"
code=$?
printf '%s\n' "$out"
cat "$err" >&2
if grep -Eq 'Sanitizer|runtime error' "$err"; then
  echo "run_json.sh: a sanitizer report from $1" >&2; rm -f "$err"; exit 1
fi
rm -f "$err"
[ "$code" -eq 0 ] || { echo "run_json.sh: $1 exited with code $code" >&2; exit 1; }
printf '%s\n' "$out" | tail -n 1 | grep -Eq "$re" || {
  echo "run_json.sh: $1's last line does not match $re" >&2; exit 1; }
