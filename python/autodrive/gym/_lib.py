"""cffi binding of the simulator's learning API (ABI mode on libautodrive_sim_core.so): the C
declarations come from the one header, sim/mujoco_hil/include/autodrive_sim_api.h, between its
CFFI markers; nothing is marshalled by hand."""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path
from typing import Any

import cffi

from autodrive.core.settings import settings

HEADER = settings().sim_api_header
LIB_NAME = "libautodrive_sim_core.so"
PRESETS = ("release", "dev", "asan")


def declarations(header: Path = HEADER) -> str:
    """The header's text between "/* CFFI-BEGIN */" and "/* CFFI-END */"."""
    text = header.read_text()
    begin, end = text.find("/* CFFI-BEGIN */"), text.find("/* CFFI-END */")
    if begin < 0 or end < begin:
        raise RuntimeError(f"{header}: no CFFI-BEGIN / CFFI-END markers")
    return text[begin + len("/* CFFI-BEGIN */") : end]


def find_library(lib_name: str, target_hint: str) -> Path:
    """lib_name in $AUTODRIVE_BUILD/lib, else in build/<release|dev|asan>/lib of the tree; the
    error names every place looked in and what to build (target_hint)."""
    build = os.environ.get("AUTODRIVE_BUILD")
    candidates = [Path(build) / "lib" / lib_name] if build else []
    candidates += [settings().preset_build(p) / "lib" / lib_name for p in PRESETS]
    for c in candidates:
        if c.is_file():
            return c
    raise FileNotFoundError(
        f"{lib_name} not found (looked in {', '.join(str(c) for c in candidates)}): build the "
        f"target {target_hint}"
    )


def library_path() -> Path:
    """The simulator core library (see find_library)."""
    return find_library(
        LIB_NAME, "autodrive_sim_core, e.g. cmake --build build/release --target autodrive_sim_core"
    )


@lru_cache(maxsize=1)
def load() -> tuple[Any, Any]:
    """(ffi, lib): the FFI with the API's declarations and the opened library."""
    ffi = cffi.FFI()
    ffi.cdef(declarations())
    return ffi, ffi.dlopen(str(library_path()))
