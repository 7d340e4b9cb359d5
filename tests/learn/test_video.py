"""Videos of episodes (issue 36): EpisodeVideo and RecordEpisodes write MP4s through the
simulator's own writer (ad_video_*, Debian's ffmpeg) that OpenCV decodes with one frame per
frame given, at the env's rate of sim time, stamped with the sim time; bad frames and sizes are
clear errors."""

from pathlib import Path

import cv2
import numpy as np
import pytest

from autodrive.gym.envs import LaneKeepingEnv
from autodrive.gym.video import EpisodeVideo, RecordEpisodes
from autodrive.gym.world import SimError


def decoded(path: Path) -> tuple[list[np.ndarray], float]:
    cap = cv2.VideoCapture(str(path))
    assert cap.isOpened(), f"{path}: OpenCV cannot open it"
    frames = []
    ok, f = cap.read()
    while ok:
        frames.append(f)
        ok, f = cap.read()
    return frames, float(cap.get(cv2.CAP_PROP_FPS))


def test_episode_video_frames_and_stamp(tmp_path: Path) -> None:
    path = tmp_path / "grey.mp4"
    with EpisodeVideo(path, 64, 48, 10.0) as v:
        for k in range(12):
            v.add(np.full((48, 64, 3), 20 * k, np.uint8), t_s=0.1 * k if k % 2 else None)
    frames, fps = decoded(path)
    assert len(frames) == 12 and fps == pytest.approx(10.0)
    # odd frames carry the stamp (white digits top-left), even ones are flat grey
    assert frames[3][1:6, 1:12].max() > 200 and frames[2][1:6, 1:12].max() < 60
    assert abs(int(frames[11][40, 40, 0]) - 220) < 8, "the picture itself changed"


def test_bad_frames_and_sizes(tmp_path: Path) -> None:
    with pytest.raises(SimError, match="bad size 63x48"):
        EpisodeVideo(tmp_path / "odd.mp4", 63, 48, 10.0)
    v = EpisodeVideo(tmp_path / "v.mp4", 64, 48, 10.0)
    with pytest.raises(ValueError, match="expected"):
        v.add(np.zeros((48, 64), np.uint8))
    v.close()
    v.close()
    with pytest.raises(SimError, match="closed"):
        v.add(np.zeros((48, 64, 3), np.uint8))


def test_record_episodes(tmp_path: Path) -> None:
    env = RecordEpisodes(LaneKeepingEnv(render_mode="rgb_array"), tmp_path)
    for seed in (0, 1):
        env.reset(seed=seed)
        for _ in range(10):
            env.step(np.array([0.6, 0.0], np.float32))
    env.close()
    for n in (0, 1):
        frames, fps = decoded(tmp_path / f"episode-{n:04d}.mp4")
        assert len(frames) == 11 and fps == pytest.approx(20.0)  # reset + 10 steps of 50 ms
        assert frames[0].shape == (120, 160, 3)
    with pytest.raises(ValueError, match="rgb_array"):
        RecordEpisodes(LaneKeepingEnv(), tmp_path)
