"""Readers of the files a run leaves behind: numeric CSVs (path.csv, route.csv,
trajectory.csv, gt.csv) and the saved occupancy map (map_server YAML + binary PGM). Errors are
ValueError naming the file and what is wrong."""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
import yaml

Column = npt.NDArray[np.float64]


def read_columns(
    path: Path | str, need: list[str], missing: float | None = None
) -> dict[str, Column]:
    """The named numeric columns of a CSV with a header; empty cells are `missing` when it is
    given, an error otherwise."""
    if not os.path.isfile(path):
        raise ValueError(f"'{path}' does not exist")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if rows and any(k not in rows[0] for k in need):
        raise ValueError(f"'{path}' lacks columns {need} (has {list(rows[0].keys())})")
    try:
        return {
            k: np.array(
                [missing if missing is not None and not r[k] else float(r[k]) for r in rows]
            )
            for k in need
        }
    except ValueError as e:
        raise ValueError(f"'{path}': non-numeric value ({e})") from None


def has_column(path: Path | str, name: str) -> bool:
    with open(path) as f:
        return name in (c.strip() for c in f.readline().split(","))


@dataclass(frozen=True)
class OccupancyMap:
    image: npt.NDArray[np.uint8]  # rows top to bottom, 0 occupied .. 255 free
    resolution_m: float  # per pixel
    origin: tuple[float, float]  # world position of the lower-left pixel [m]

    def extent(self) -> tuple[float, float, float, float]:
        h, w = self.image.shape
        x0, y0 = self.origin
        return x0, x0 + w * self.resolution_m, y0, y0 + h * self.resolution_m


def _pgm_header(data: bytes, img: str) -> tuple[list[str], int]:
    toks: list[str] = []
    i = 0
    while len(toks) < 4:
        while i < len(data) and chr(data[i]).isspace():
            i += 1
        if i < len(data) and data[i] == ord("#"):
            while i < len(data) and data[i] != ord("\n"):
                i += 1
            continue
        j = i
        while j < len(data) and not chr(data[j]).isspace():
            j += 1
        if j == i:
            raise ValueError(f"map image '{img}': truncated PGM header")
        toks.append(data[i:j].decode("ascii", "replace"))
        i = j
    return toks, i


def read_occupancy(yaml_path: Path | str) -> OccupancyMap:
    try:
        with open(yaml_path) as f:
            m = yaml.safe_load(f)
    except OSError as e:
        raise ValueError(f"map '{yaml_path}': {e.strerror}") from None
    except yaml.YAMLError as e:
        raise ValueError(f"map '{yaml_path}': not valid YAML ({e})") from None
    for k in ("image", "resolution", "origin"):
        if not isinstance(m, dict) or k not in m:
            raise ValueError(f"map '{yaml_path}': missing key '{k}'")
    img = str(m["image"])
    if not os.path.isabs(img):
        img = os.path.join(os.path.dirname(yaml_path), img)
    try:
        data = open(img, "rb").read()
    except OSError as e:
        raise ValueError(f"map image '{img}': {e.strerror}") from None
    toks, i = _pgm_header(data, img)
    if toks[0] != "P5":
        raise ValueError(f"map image '{img}': only binary PGM (P5) is supported, got '{toks[0]}'")
    w, h = int(toks[1]), int(toks[2])
    px = np.frombuffer(data[i + 1 : i + 1 + w * h], dtype=np.uint8)
    if px.size != w * h:
        raise ValueError(f"map image '{img}': truncated pixel data")
    origin = m["origin"]
    return OccupancyMap(px.reshape(h, w), float(m["resolution"]), (origin[0], origin[1]))
