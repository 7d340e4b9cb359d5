"""The curvature augmentation (augment.CurveWarp, `tools/pilot train --curve-max`): a straight
lane line drawn on the ground through the sim's camera model comes out of the warp on the arc of
radius 1/dk (left for dk > 0, right for dk < 0) at the same offset from base_link's path, to
within 1 px of the network's picture; dk 0 leaves the picture and the label as they were; the
label is the steering of the recorded curvature plus dk (a straight gains atan(wheelbase dk));
a dataset without camera intrinsics is refused; curve_max_dk 0 (the shipped recipe) is no warp."""

from __future__ import annotations

import math

import cv2
import numpy as np

from autodrive.core import vehicle
from autodrive.learn.pilot import augment, train
from autodrive.learn.pilot.spec import crop_resize

FX = 530.6765106850642  # [px] the sim's front camera (fovy 48.67 deg at 480 px), as recorded
SPEC = train.DEFAULT_INPUT


def project(warp: augment.CurveWarp, x: float, y: float) -> tuple[float, float]:
    """A ground point (ahead of base_link, left) [m] -> the source frame's pixel (u, v)."""
    d = x - warp.cam_ahead_m
    return (SPEC.source_width / 2 - warp.fx_px * y / d,
            SPEC.source_height / 2 + warp.fy_px * warp.cam_height_m / d)  # fmt: skip


def to_small(u: float, v: float) -> tuple[float, float]:
    sy = (SPEC.source_height - SPEC.crop_top_px - SPEC.crop_bottom_px) / SPEC.height
    return u * SPEC.width / SPEC.source_width - 0.5, (v - SPEC.crop_top_px) / sy - 0.5


def line_image(warp: augment.CurveWarp, offset_m: float) -> np.ndarray:
    big = np.zeros((SPEC.source_height, SPEC.source_width, 3), np.uint8)
    pts = [project(warp, x, offset_m) for x in np.linspace(0.35, 2.0, 400)]
    # cv2 draws at pixel-centre coordinates: pixel i spans [i, i + 1) of project()'s
    poly = np.array([[round((u - 0.5) * 16), round((v - 0.5) * 16)] for u, v in pts], np.int32)
    cv2.polylines(big, [poly], False, (255, 255, 255), 12, cv2.LINE_AA, shift=4)
    return crop_resize(big, SPEC)


def arc_columns(warp: augment.CurveWarp, offset_m: float, dk: float) -> dict[int, float]:
    """Expected small-image column of the line bent by dk, per small-image row."""
    r = 1.0 / dk
    out: dict[int, float] = {}
    for th in np.linspace(0.0, 1.2, 4000):  # along the arc at distance r - offset from its centre
        rad = abs(r) - math.copysign(offset_m, r)
        x, y = rad * math.sin(th), r - math.copysign(rad * math.cos(th), r)
        if x <= warp.cam_ahead_m + 0.05:
            continue
        u, v = to_small(*project(warp, x, y))
        row = int(round(v))
        if 0 <= row < SPEC.height and 3 <= u < SPEC.width - 3:  # the whole line in the row
            out.setdefault(row, u)
    return out


def centre(row: np.ndarray) -> float:
    """The line's column in one picture row: the intensity-weighted mean [px]."""
    w = row[:, 0].astype(float)
    return float((w * np.arange(len(w))).sum() / w.sum())


def test_curve_warp_geometry() -> None:
    manifest = {"camera": {"fx_px": FX, "fy_px": FX}}
    warp = train.curve_warp(manifest, SPEC, train.TrainConfig(curve_max_dk=0.75))
    assert warp is not None and warp.max_dk == 0.75
    assert train.curve_warp(manifest, SPEC, train.TrainConfig()) is None
    try:
        train.curve_warp({}, SPEC, train.TrainConfig(curve_max_dk=0.5))
        raise AssertionError("a manifest without camera intrinsics was accepted")
    except ValueError as e:
        assert "camera" in str(e), e
    v = vehicle.load()
    wb, lim = v.number("wheelbase_m"), v.number("steer_limit_rad")
    # labels: dk 0 keeps it; a straight gains atan(wheelbase dk); signs follow dk
    for s in (-0.4, 0.0, 0.36):
        assert math.isclose(warp.steering(s, 0.0), s, abs_tol=1e-12)
    assert math.isclose(warp.steering(0.0, 0.5), math.atan(wb * 0.5) / lim, rel_tol=1e-12)
    assert warp.steering(0.36, 0.5) > 0.36 and warp.steering(0.36, -0.5) < 0.36
    # dk 0: the identity
    img = line_image(warp, 0.08)
    mx, my = warp.maps(0.0)
    same = cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    assert np.abs(same.astype(int) - img.astype(int)).max() <= 2
    # a straight line 0.08 m left of base_link's path, bent each way
    straight = {r: centre(img[r]) for r in range(SPEC.height) if img[r].max() > 60}
    for dk in (0.75, -0.75, 0.4):
        mx, my = warp.maps(dk)
        out = cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
        want = arc_columns(warp, 0.08, dk)
        errs, moved = [], []
        for row, u in want.items():
            seen = 1 <= my[row, int(u)] <= SPEC.height - 2  # the frame saw that ground
            if seen and out[row].max() > 60:
                got = centre(out[row])
                errs.append(abs(got - u))
                if row in straight:
                    moved.append(got - straight[row])
        assert len(errs) >= SPEC.height // 3, (dk, len(errs))
        assert max(errs) <= 1.0, (dk, max(errs))
        # the far rows (top of the picture) moved the way the road bends: left = smaller column
        assert moved and math.copysign(1.0, -float(np.mean(moved))) == math.copysign(1.0, dk)
        print(f"dk {dk:+.2f} 1/m: line on the arc within {max(errs):.2f} px over {len(errs)} rows, "
              f"moved {np.mean(moved):+.1f} px on average")  # fmt: skip
