#!/bin/sh
# The learning library exports its API alone (issue 42): every defined dynamic symbol of
# libautodrive_sim_core.so starts with the API's prefix ad_ (api/include/autodrive_sim_api.h),
# apart from the linker's own markers. Usage: check_api_exports.sh LIBRARY
set -eu
lib=$1
syms=$(nm -D --defined-only "$lib" | awk '{ print $NF }')
[ -n "$syms" ] || { echo "$lib: no dynamic symbols at all" >&2; exit 1; }
echo "$syms" | grep -q '^ad_world_create$' || { echo "$lib: ad_world_create not exported" >&2; exit 1; }
other=$(echo "$syms" | grep -v '^ad_' | grep -vxE '_init|_fini|_edata|_end|__bss_start' || true)
if [ -n "$other" ]; then
  echo "$lib exports symbols outside the API (prefix ad_):" >&2
  echo "$other" >&2
  exit 1
fi
echo "$lib exports $(echo "$syms" | grep -c '^ad_') API symbols and nothing else"
