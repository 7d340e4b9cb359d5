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
  the bend's outer side) is filled with the frame's median colour, the road's asphalt.
- Domain randomisation (an option, `tools/pilot train --randomise`, `tools/pilot dagger`'s
  default; Randomise): what the simulator cannot vary per frame, on the small frame: the light's
  colour (per-channel gains), exposure (gain and gamma, clipped as a sensor clips), blur and
  noise, the camera's pose within the mount's tolerance (pitch and roll as the picture's
  rotation about the principal point and its vertical shift; yaw as a sideways shift whose label
  correction is the shift's), the road's texture (the asphalt's pixels tinted towards another
  of the kit's surfaces, with a seeded grain) and distractors beside the road (cone- and
  box-coloured blobs at the picture's outer edges). The simulator's own (light level, camera
  noise and blur) are drawn per recording (tools/pilot dagger, SimRandom)."""

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


# The camera mount's tolerance: vehicle/nigel.params gives the camera's pose, no tolerance; we
# take +-1 deg about each axis (a 3D-printed mount on M2 screws) and say so in the docs.
MOUNT_TOLERANCE_DEG = 1.0
# the kit's surfaces (maps/kit.yaml, rgba 0..1 as BGR 8-bit) a road can be tinted towards
KIT_SURFACES_BGR = {
    "asphalt": (69.0, 64.0, 64.0),
    "dirt": (51.0, 84.0, 115.0),
    "worn": (110.0, 105.0, 100.0),  # asphalt weathered light grey (not a kit surface: a variant)
}
# distractor colours (BGR): the kit's cone and box, a parked car's red and blue
DISTRACTORS_BGR = ((0.0, 102.0, 255.0), (25.0, 153.0, 230.0), (40.0, 40.0, 200.0), (200, 80, 30))


@dataclass(frozen=True)
class Randomise:
    """Image-level domain randomisation of a small BGR frame (each part with probability p)."""

    fx_small_px: float = 0.0  # focal length at the small frame's width [px] (0: no pose jitter)
    fy_small_px: float = 0.0  # [px] at the small frame's height
    cy_small_px: float = 0.0  # the principal point's row in small-frame rows (above: < 0)
    gain_per_px: float = 0.0  # steering per px of sideways shift (Augment's)
    p: float = 0.3
    colour_gain: float = 0.15  # per-channel gain in 1 +- this (the light's colour)
    exposure_ev: float = 0.7  # gain 2^U(-ev, ev) ...
    gamma: tuple[float, float] = (0.7, 1.4)  # ... and a gamma in this range
    blur_sigma_px: float = 1.2  # Gaussian blur up to this sigma [px of the small frame]
    noise_sigma: float = 6.0  # Gaussian noise up to this sigma [8-bit levels]
    mount_tolerance_deg: float = MOUNT_TOLERANCE_DEG  # pitch, roll, yaw jitter within +-this
    texture_strength: float = 0.6  # the road's tint towards a surface, up to this fraction
    road_luma_max: float = 110.0  # pixels darker than this [8-bit luma], low chroma: the road
    max_distractors: int = 2

    def __call__(self, img: U8, steering: float, rng: np.random.Generator) -> tuple[U8, float]:
        h, w = img.shape[:2]
        out = img
        if self.fx_small_px > 0 and rng.random() < self.p:  # the camera's pose in its mount
            tol = math.radians(self.mount_tolerance_deg)
            pitch, roll, yaw = (float(v) for v in rng.uniform(-tol, tol, 3))
            dx = self.fx_small_px * math.tan(yaw)
            dy = self.fy_small_px * math.tan(pitch)
            m = cv2.getRotationMatrix2D((w / 2.0, self.cy_small_px), math.degrees(roll), 1.0)
            m[0, 2] += dx
            m[1, 2] += dy
            out = cv2.warpAffine(out, m, (w, h), borderMode=cv2.BORDER_REPLICATE)
            steering -= self.gain_per_px * dx
        f = out.astype(np.float32)
        if rng.random() < self.p:  # road texture: the asphalt tinted, with a grain
            grey = f.mean(axis=2)
            chroma = f.max(axis=2) - f.min(axis=2)
            road = (grey < self.road_luma_max) & (chroma < 25.0)
            names = sorted(KIT_SURFACES_BGR)
            tint = np.asarray(KIT_SURFACES_BGR[names[int(rng.integers(len(names)))]], np.float32)
            a = np.float32(rng.uniform(0.0, self.texture_strength))
            grain = cv2.GaussianBlur(rng.normal(0.0, 12.0, (h, w)).astype(np.float32), (0, 0), 1.5)
            mixed = (1 - a) * f + a * (tint + grain[:, :, None])
            f = np.where(road[:, :, None], mixed, f)
        if rng.random() < self.p:  # distractors beside the road: at the picture's outer edges
            for _ in range(int(rng.integers(1, self.max_distractors + 1))):
                side = int(rng.integers(2))
                bw, bh = int(rng.integers(6, 16)), int(rng.integers(6, 20))
                x0 = int(rng.integers(0, max(1, w // 8 - bw // 2)))
                x0 = x0 if side == 0 else w - bw - x0
                y0 = int(rng.integers(0, max(1, h // 2)))
                colour = DISTRACTORS_BGR[int(rng.integers(len(DISTRACTORS_BGR)))]
                f[y0 : y0 + bh, x0 : x0 + bw] = np.asarray(colour, np.float32)
        if rng.random() < self.p:  # the light's colour
            f *= rng.uniform(1 - self.colour_gain, 1 + self.colour_gain, 3).astype(np.float32)
        if rng.random() < self.p:  # exposure: gain and gamma, clipped as a sensor clips
            g = np.float32(2.0 ** rng.uniform(-self.exposure_ev, self.exposure_ev))
            gam = np.float32(rng.uniform(*self.gamma))
            f = 255.0 * np.clip(f * g / 255.0, 0.0, 1.0) ** gam
        if rng.random() < self.p:
            f = cv2.GaussianBlur(f, (0, 0), float(rng.uniform(0.3, self.blur_sigma_px)))
        if rng.random() < self.p:
            f = f + rng.normal(0.0, rng.uniform(0.0, self.noise_sigma), f.shape).astype(np.float32)
        res: U8 = np.clip(f, 0, 255).astype(np.uint8)
        return res, float(steering)


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
    randomise: Randomise | None = None  # domain randomisation (None: off, the shipped recipe)

    def __call__(self, img: U8, steering: float, rng: np.random.Generator) -> tuple[U8, float]:
        out = img
        h, w = img.shape[:2]
        if self.curve is not None and rng.random() < self.curve.p_curve:
            out, steering = self.curve(out, steering, rng)
        if self.randomise is not None:
            out, steering = self.randomise(out, steering, rng)
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
