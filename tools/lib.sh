# Shared helpers for the tools/ entry points (sourced, not run).
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PY="$ROOT/.venv/bin/python"
log() { printf '[%s] %s\n' "$(basename "$0")" "$*"; }
die() { printf '[%s] ERROR: %s\n' "$(basename "$0")" "$*" >&2; exit 1; }
# Configures (once) and builds a preset of the host build: dev, release or asan.
build_host() {
  local preset="$1"; shift
  if [ ! -f "$ROOT/build/$preset/build.ninja" ]; then
    log "configuring preset $preset"
    cmake --preset "$preset" -S "$ROOT" >/dev/null || die "cmake configure ($preset) failed"
  fi
  log "building preset $preset"
  cmake --build "$ROOT/build/$preset" "$@" || die "build ($preset) failed"
}
# Builds the AVR firmware (.elf/.hex) if its CMake project exists.
build_avr() {
  if [ -f "$ROOT/firmware/nano/avr/CMakeLists.txt" ]; then
    if [ ! -f "$ROOT/build/avr/build.ninja" ]; then
      log "configuring AVR firmware (avr-gcc)"
      cmake -G Ninja -S "$ROOT/firmware/nano/avr" -B "$ROOT/build/avr" \
        --toolchain "$ROOT/cmake/avr-gcc.cmake" -DCMAKE_BUILD_TYPE=MinSizeRel >/dev/null \
        || die "AVR configure failed"
    fi
    log "building AVR firmware"
    cmake --build "$ROOT/build/avr" || die "AVR firmware build failed"
  fi
}
# Makes sure the project venv with autodrive_tools exists (tools/setup creates it).
need_venv() {
  "$PY" -c 'import autodrive_tools' 2>/dev/null || "$ROOT/tools/setup" >&2 \
    || die "tools/setup failed"
}
