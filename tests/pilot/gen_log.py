"""A small generated LCM log for the pilot tests: front-camera JPEGs of a drawn lane whose bend
follows the steering, and ground truth whose heading turns `laps` full turns (so the recorder
counts laps), with the expert's steering a smooth function of time. No camera frames with
cameras=False (record must refuse such a log)."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import lcm
import numpy as np

from autodrive.core import channels
from autodrive.core import lcmtypes


def lane_image(steering: float, rng: np.random.Generator) -> bytes:
    img = np.full((480, 640, 3), (150, 110, 90), np.uint8)  # sky
    img[280:] = (60, 60, 60)  # road
    bend = steering * 260.0
    for side in (-1, 1):
        pts = []
        for y in range(280, 480, 10):
            u = (480 - y) / 200.0  # 0 near, 1 at the horizon
            x = 320 + side * (300 - 260 * u) + bend * u * u
            pts.append((int(x), y))
        cv2.polylines(img, [np.array(pts, np.int32)], False, (240, 240, 240), 6)
    noise = rng.normal(0, 2, img.shape)
    img = np.clip(img + noise, 0, 255).astype(np.uint8)
    ok, jpg = cv2.imencode(".jpg", img)
    assert ok
    return bytes(jpg.tobytes())


def write(
    path: Path, build: Path, laps: int = 2, frames_per_lap: int = 60, cameras: bool = True
) -> int:
    """Writes the log; returns the number of camera frames."""
    t = lcmtypes.load(build)
    veh = channels.vehicle_name(1)
    log = lcm.EventLog(str(path), "w", overwrite=True)
    rng = np.random.default_rng(0)
    n = laps * frames_per_lap
    frames = 0
    for i in range(n):
        utime = 100_000 + i * 66_667  # 15 Hz
        phase = i / frames_per_lap  # laps so far
        steer = 0.5 * math.sin(2 * math.pi * 3 * phase)
        for k in range(3):  # ground truth at 45 Hz, a little before each frame
            g = t.ground_truth_t()
            g.utime = utime - 30_000 + k * 10_000
            g.vehicle = veh
            g.position_m = [math.cos(2 * math.pi * phase), math.sin(2 * math.pi * phase), 0.0]
            g.orientation_wxyz = [1.0, 0.0, 0.0, 0.0]
            g.yaw_rad = math.remainder(2 * math.pi * phase + 0.1, 2 * math.pi)
            g.linear_velocity_m_s = [0.2, 0.0, 0.0]
            g.angular_velocity_rad_s = [0.0, 0.0, 0.0]
            g.steering_angle_rad = 0.0
            g.command_throttle = 0.8
            g.command_steering = steer + (0.3 if i % 20 < 3 else 0.0)  # perturbed now and then
            g.expert_steering = steer
            log.write_event(g.utime, channels.channel("GROUND_TRUTH", veh), g.encode())
        if cameras:
            m = t.compressed_image_t()
            m.utime = utime
            m.frame_id = "camera_front"
            m.format = "jpeg"
            m.width_px, m.height_px = 640, 480
            m.data = lane_image(steer, rng)
            m.size_bytes = len(m.data)
            log.write_event(utime, channels.channel("CAM_FRONT", veh), m.encode())
            frames += 1
    log.close()
    return frames
