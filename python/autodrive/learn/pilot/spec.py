"""The model's input contract with the C++ `autodrive-pilot` ("Cloning model"): the JSON sidecar
`NAME.json` beside `NAME.onnx` is the one place of the preprocessing. Training, analysis and
the C++ `autodrive-pilot` all apply exactly what it says:

    decode JPEG (BGR) -> crop rows [crop_top_px, source_height - crop_bottom_px)
    -> cv2.resize to (width, height), INTER_AREA -> colour convert (BGR -> yuv|bgr|rgb)
    -> x * scale -> (x - mean) / std per channel -> NCHW float32

`crop_resize` and `normalise` are the two halves (training augments the small BGR image
between them: flips, brightness and shifts commute with the crop and resize); `preprocess`
is both. What the network does with this input (the shipped recipe: it reads the Y channel
only and normalises each frame to mean 0, std 1) is inside the ONNX graph (model.py), so no
runtime has to repeat it."""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

U8 = npt.NDArray[np.uint8]
F32 = npt.NDArray[np.float32]

COLOURS = ("yuv", "bgr", "rgb")
OPSET = 11  # the ONNX opset of our exports (OpenCV 4.6's DNN reads 11..13)


class SidecarError(ValueError):
    """A sidecar that is missing a key or holds a value we cannot use; names the file."""


@dataclass(frozen=True)
class InputSpec:
    source_width: int  # [px] camera frame
    source_height: int  # [px]
    crop_top_px: int  # rows cut off at the top (sky, horizon)
    crop_bottom_px: int  # rows cut off at the bottom (bonnet)
    width: int  # [px] network input
    height: int  # [px]
    colour: str  # "yuv" | "bgr" | "rgb", converted from OpenCV's BGR
    scale: float  # multiplies the 8-bit levels (1/255: [0, 1])
    mean: tuple[float, float, float] = (0.0, 0.0, 0.0)  # per channel, after scale
    std: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def check(self, where: str) -> None:
        if self.colour not in COLOURS:
            raise SidecarError(f"{where}: input.colour '{self.colour}' is not one of {COLOURS}")
        if not 0 <= self.crop_top_px < self.source_height - self.crop_bottom_px:
            raise SidecarError(
                f"{where}: crop_top_px {self.crop_top_px} / crop_bottom_px "
                f"{self.crop_bottom_px} leave no rows of {self.source_height}"
            )
        if self.crop_bottom_px < 0 or self.width < 8 or self.height < 8:
            raise SidecarError(f"{where}: crop_bottom_px < 0 or input smaller than 8x8 px")
        if any(s <= 0 for s in self.std) or self.scale <= 0:
            raise SidecarError(f"{where}: scale and every std must be > 0")


def crop_resize(bgr: U8, spec: InputSpec) -> U8:
    """The first half: crop rows, then INTER_AREA resize to the network's size (uint8 BGR)."""
    h, w = bgr.shape[:2]
    if (w, h) != (spec.source_width, spec.source_height):
        raise ValueError(
            f"frame is {w}x{h} px, the model takes {spec.source_width}x{spec.source_height}"
        )
    rows = bgr[spec.crop_top_px : h - spec.crop_bottom_px]
    out: U8 = cv2.resize(rows, (spec.width, spec.height), interpolation=cv2.INTER_AREA)
    return out


_CONVERT = {"yuv": cv2.COLOR_BGR2YUV, "rgb": cv2.COLOR_BGR2RGB}


def normalise(small_bgr: U8, spec: InputSpec) -> F32:
    """The second half: colour convert, scale, mean/std, HWC -> CHW (float32)."""
    img = small_bgr if spec.colour == "bgr" else cv2.cvtColor(small_bgr, _CONVERT[spec.colour])
    x = img.astype(np.float32) * np.float32(spec.scale)
    x = (x - np.asarray(spec.mean, np.float32)) / np.asarray(spec.std, np.float32)
    chw: F32 = np.ascontiguousarray(x.transpose(2, 0, 1))
    return chw


def preprocess(bgr: U8, spec: InputSpec) -> F32:
    """A decoded camera frame (BGR, source size) to the network's input [3, H, W]."""
    return normalise(crop_resize(bgr, spec), spec)


def decode_jpeg(data: bytes, name: str) -> U8:
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    if img is None:
        raise ValueError(f"{name}: not a decodable JPEG/PNG image")
    out: U8 = img
    return out


@dataclass
class Sidecar:
    input: InputSpec
    opset: int = OPSET
    onnx_sha256: str = ""
    trained: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        d = asdict(self)
        d["input"]["mean"] = list(self.input.mean)
        d["input"]["std"] = list(self.input.std)
        return d


def sha256_file(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def write_sidecar(path: Path, sidecar: Sidecar) -> None:
    path.write_text(json.dumps(sidecar.to_json(), indent=2) + "\n")


def read_sidecar(path: Path) -> Sidecar:
    """Reads and checks a sidecar; a clear SidecarError names the file and the bad key."""
    try:
        doc = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise SidecarError(f"{path}: cannot read the model's sidecar JSON ({e})") from e
    try:
        i = doc["input"]
        spec = InputSpec(
            source_width=int(i["source_width"]),
            source_height=int(i["source_height"]),
            crop_top_px=int(i["crop_top_px"]),
            crop_bottom_px=int(i["crop_bottom_px"]),
            width=int(i["width"]),
            height=int(i["height"]),
            colour=str(i["colour"]),
            scale=float(i["scale"]),
            mean=_three(i["mean"], path, "mean"),
            std=_three(i["std"], path, "std"),
        )
        out = Sidecar(
            input=spec,
            opset=int(doc["opset"]),
            onnx_sha256=str(doc.get("onnx_sha256", "")),
            trained=dict(doc.get("trained", {})),
        )
    except (KeyError, TypeError, ValueError) as e:
        raise SidecarError(f"{path}: missing or bad key {e}") from e
    spec.check(str(path))
    return out


def _three(v: Any, path: Path, key: str) -> tuple[float, float, float]:
    if not isinstance(v, list) or len(v) != 3:
        raise SidecarError(f"{path}: input.{key} must be a list of 3 numbers")
    return (float(v[0]), float(v[1]), float(v[2]))
