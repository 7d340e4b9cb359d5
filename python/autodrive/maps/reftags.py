"""A map's reference tags (tag36h11 prints on the floor for the overhead cameras' map
calibration): their textures, drawn by libapriltag itself (Debian's libapriltag3, through
ctypes: the same bits the Eye decodes and the simulator prints on the cars' roofs, sim_tags.c),
and their entry in the sidecar (the Eye's reference tag list: id, x_m, y_m,
z_m, yaw_rad, size_m)."""

from __future__ import annotations

import ctypes
import ctypes.util
import math
from functools import lru_cache
from typing import Any

import numpy as np
from PIL import Image

from autodrive.maps.model import REFERENCE_TAG_TOP_M, ReferenceTagSpec
from autodrive.maps.textures import png_bytes

PX_PER_CELL = 8  # as the simulator's roof tags (sim.c: sim_tags_write_png(..., 8, ...))
CELLS = 10  # tag36h11 with its white border: 10 x 10 cells, the black square is 8
BLACK_CELLS = 8


class _ImageU8(ctypes.Structure):
    _fields_ = [
        ("width", ctypes.c_int32),
        ("height", ctypes.c_int32),
        ("stride", ctypes.c_int32),
        ("buf", ctypes.POINTER(ctypes.c_uint8)),
    ]


@lru_cache(maxsize=1)
def _libapriltag() -> Any:
    name = ctypes.util.find_library("apriltag")
    if name is None:
        raise RuntimeError("libapriltag not found: install libapriltag3 (tools/setup)")
    lib = ctypes.CDLL(name)
    lib.tag36h11_create.restype = ctypes.c_void_p
    lib.apriltag_to_image.restype = ctypes.POINTER(_ImageU8)
    lib.apriltag_to_image.argtypes = [ctypes.c_void_p, ctypes.c_uint32]
    return lib


@lru_cache(maxsize=1)
def _tag36h11() -> Any:
    """The family, made once: libapriltag 3.3 exports neither tag36h11_destroy nor
    image_u8_destroy, so the family and the few 10 x 10 images stay until the process ends."""
    return _libapriltag().tag36h11_create()


def texture_name(tag_id: int) -> str:
    return f"reftag36h11_{tag_id}"


def png(tag_id: int) -> bytes:
    """The tag's 10 x 10 cells (white border included), PX_PER_CELL pixels each, grey as RGB;
    image up = the top of the print."""
    im = _libapriltag().apriltag_to_image(_tag36h11(), tag_id).contents
    cells = np.array(
        [[im.buf[y * im.stride + x] for x in range(im.width)] for y in range(im.height)],
        dtype=np.uint8,
    )
    if cells.shape != (CELLS, CELLS):
        raise RuntimeError(f"libapriltag drew tag36h11 {tag_id} as {cells.shape} cells")
    big = np.kron(cells, np.ones((PX_PER_CELL, PX_PER_CELL), dtype=np.uint8))
    return png_bytes(Image.fromarray(np.stack([big] * 3, axis=-1), "RGB"))


def sidecar(tags: list[ReferenceTagSpec]) -> list[dict[str, Any]]:
    """The Eye's reference tag entries (calibrate-map --tags: id, x_m, y_m, z_m, yaw_rad,
    size_m)."""
    return [
        {
            "id": t.id,
            "x_m": t.centre_m[0],
            "y_m": t.centre_m[1],
            "z_m": REFERENCE_TAG_TOP_M,
            "yaw_rad": math.radians(t.yaw_deg),
            "size_m": t.size_m,
        }
        for t in tags
    ]
