"""Balancing and augmentation of the training frames (on the small BGR image between the
sidecar's two preprocessing halves; all of it seeded through the numpy Generator given).

- Balance: frames are drawn with weights 1/count of their steering bin, capped at max_ratio
  times the weight of the commonest bin, so the many straight-ahead frames do not drown the
  curves and recoveries. A low cap matters: with a flat histogram (a high cap) the network
  learns curve-sized answers for the frames just before a curve and turns in early.
- Mirror (p 0.5): flipped left-right, steering negated.
- Brightness (p 0.5): all levels times U(0.3, 1.3); shadow (p 0.5): a random slanted band
  darkened to 0.25-0.8 of its levels. A dark band across a solid line makes it look broken,
  like the dashed centre line, one more way (with the luma-only input, model.py) to keep the
  network from telling the two lines apart.
- Shift (p 0.5): up to max_shift_px sideways (and up to 2 px up/down), with a steering
  correction of
  -gain_per_px * dx: a sideways shift looks like a heading error of dx / fx [rad], which pure
  pursuit answers with (2 wheelbase / lookahead) / steer_limit per rad (normalised).
- Curvature (an option, p_curve 0 in the shipped recipe; `tools/pilot train --curve-max`): the
  ground in the picture bent by an extra curvature dk ~ U(-max, max) [1/m] (CurveWarp): each
  pixel's ground point (X ahead of base_link, Y left) shows what the frame had at (arc length,
  offset) of a circle of radius 1/dk through base_link, so a straight becomes a curve either way
  with its lines where they were (the dashed centre line on the outside of a right-hand curve
  too); the label becomes the steering of the curvature plus dk, atan(wheelbase (k + dk)). Ground
  the frame did not see (outside its view: 20-30 % of the picture at |dk| 0.5-0.75, mostly on
  the bend's outer side) is filled with the frame's median colour, the road's asphalt."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
import numpy.typing as npt

from autodrive.learn.pilot.spec import U8

F64 = npt.NDArray[np.float64]

BIN_WIDTH = 0.05  # steering histogram bin [normalised]
# A rare frame is drawn at most this many times as often as a common one. 3, not 20: on the same
# 2.6 laps, 20 made the straights 0.4-0.6 m before a curve steer +0.041 into it (3: +0.002) and
# the car cut the first curve over the lane bound in HIL; 3 kept it inside.
DEFAULT_MAX_RATIO = 3.0


def bins(steering: F64) -> npt.NDArray[np.int64]:
    b: npt.NDArray[np.int64] = np.floor((np.clip(steering, -1, 1) + 1.0) / BIN_WIDTH).astype(
        np.int64
    )
    return b


def balance_weights(steering: F64, max_ratio: float = DEFAULT_MAX_RATIO) -> F64:
    """Sampling probabilities that flatten the steering histogram (sum 1); a frame is drawn at
    most max_ratio (>= 1) times as often as one of the commonest bin."""
    if max_ratio < 1.0:
        raise ValueError(f"balance max ratio {max_ratio}: at least 1 (1: no balancing)")
    b = bins(steering)
    counts = np.bincount(b)
    w = 1.0 / counts[b].astype(np.float64)
    w = np.minimum(w, w.min() * max_ratio)
    out: F64 = w / w.sum()
    return out


@dataclass(frozen=True)
class CurveWarp:
    """Bends the ground of a small (cropped, resized) frame by an extra curvature; the camera is
    the sim's front camera: pinhole, principal point at the frame's centre, looking level."""

    fx_px: float  # focal lengths [px] of the source frame
    fy_px: float
    source_width: int  # [px]
    source_height: int  # [px]
    crop_top_px: int  # the small frame's first source row
    crop_bottom_px: int
    width: int  # [px] of the small frame
    height: int  # [px]
    cam_ahead_m: float  # the camera ahead of base_link [m]
    cam_height_m: float  # above the ground [m]
    wheelbase_m: float
    steer_limit_rad: float
    max_dk: float = 1.0  # [1/m]; 1 bends a straight into a 1 m radius, 0.74 m curves to 0.43 m
    p_curve: float = 0.0

    def maps(self, dk: float) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
        """cv2.remap's maps (small-frame x and y of the source pixel) for curvature dk [1/m]."""
        sx = self.source_width / self.width
        sy = (self.source_height - self.crop_bottom_px - self.crop_top_px) / self.height
        u = (np.arange(self.width) + 0.5) * sx - self.source_width / 2  # [px] from the centre
        v = self.crop_top_px + (np.arange(self.height) + 0.5) * sy - self.source_height / 2
        vv, uu = np.meshgrid(np.maximum(v, 0.5), u, indexing="ij")
        d = self.fy_px * self.cam_height_m / vv  # ground ahead of the camera [m]
        x, y = d + self.cam_ahead_m, -uu * d / self.fx_px
        if abs(dk) > 1e-9:  # (x, y) on the bent road shows the frame's (arc length, offset)
            r = 1.0 / dk
            rho = np.hypot(x, y - r)
            x, y = abs(r) * np.arctan2(x, np.sign(r) * (r - y)), r - np.sign(r) * rho
        d = np.maximum(x - self.cam_ahead_m, 1e-3)
        src_u = self.source_width / 2 - self.fx_px * y / d
        src_v = self.source_height / 2 + self.fy_px * self.cam_height_m / d - self.crop_top_px
        return (src_u / sx - 0.5).astype(np.float32), (src_v / sy - 0.5).astype(np.float32)

    def steering(self, steering: float, dk: float) -> float:
        """The label for the bent road: the curvature the steering drives, plus dk."""
        k = math.tan(steering * self.steer_limit_rad) / self.wheelbase_m
        return math.atan(self.wheelbase_m * (k + dk)) / self.steer_limit_rad

    def __call__(self, img: U8, steering: float, rng: np.random.Generator) -> tuple[U8, float]:
        dk = float(rng.uniform(-self.max_dk, self.max_dk))
        mx, my = self.maps(dk)
        fill = tuple(float(c) for c in np.median(img.reshape(-1, img.shape[2]), axis=0))
        out: U8 = cv2.remap(
            img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=fill
        )
        return out, self.steering(steering, dk)


@dataclass(frozen=True)
class Augment:
    gain_per_px: float  # steering correction per px of sideways shift [normalised / px]
    # 12 px at the 200 px width: corrections up to ~0.2 on top of the expert's steering, so
    # the labels reach past the recorded loop's sharpest curve (0.36 normalised)
    max_shift_px: float = 12.0
    p_mirror: float = 0.5
    p_brightness: float = 0.5
    p_shadow: float = 0.5
    shadow_levels: tuple[float, float] = (0.25, 0.8)  # the band's levels times U(a, b)
    p_shift: float = 0.5
    curve: CurveWarp | None = None  # the curvature augmentation (None: off)

    def __call__(self, img: U8, steering: float, rng: np.random.Generator) -> tuple[U8, float]:
        out = img
        h, w = img.shape[:2]
        if self.curve is not None and rng.random() < self.curve.p_curve:
            out, steering = self.curve(out, steering, rng)
        if rng.random() < self.p_shift:
            dx = float(rng.uniform(-self.max_shift_px, self.max_shift_px))
            dy = float(rng.uniform(-2.0, 2.0))
            m = np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]], np.float32)
            out = cv2.warpAffine(out, m, (w, h), borderMode=cv2.BORDER_REPLICATE)
            steering -= self.gain_per_px * dx
        bright, shadow = rng.random() < self.p_brightness, rng.random() < self.p_shadow
        if bright or shadow:
            f = out.astype(np.float32)
            if bright:
                f *= np.float32(rng.uniform(0.3, 1.3))
            if shadow:
                x0, x1 = sorted(rng.uniform(0, w, 2))
                slope = float(rng.uniform(-1.0, 1.0)) * w / h
                xs = np.arange(w, dtype=np.float32)[None, :]
                ys = np.arange(h, dtype=np.float32)[:, None] - h / 2
                inside = (xs >= x0 + slope * ys) & (xs <= x1 + slope * ys)
                f[inside] *= np.float32(rng.uniform(*self.shadow_levels))
            out = np.clip(f, 0, 255).astype(np.uint8)
        if rng.random() < self.p_mirror:
            out = np.ascontiguousarray(out[:, ::-1])
            steering = -steering
        return out, float(np.clip(steering, -1.0, 1.0))
