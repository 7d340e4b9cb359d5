"""Videos of episodes: the simulator's own MP4 writer (sim/mujoco_hil/sensors sim_video.h,
frames piped into Debian's ffmpeg) through the learning API's ad_video_*, the same writer as
``autodrive-sim --video`` / ``--record``. Frames come at a fixed rate of sim time, so the
video's clock is the simulator's whatever the real-time factor, and each frame is stamped with
its sim time.

    env = gymnasium.make("autodrive/DrivingSchool-v0", render_mode="rgb_array")
    env = RecordEpisodes(env, Path("videos"))   # videos/episode-0000.mp4, ...
"""

from __future__ import annotations

from pathlib import Path
from types import TracebackType
from typing import Any, SupportsFloat

import gymnasium
import numpy as np
import numpy.typing as npt

from autodrive.gym import _lib
from autodrive.gym.world import ERR_BYTES, SimError


class EpisodeVideo:
    """An MP4 of width x height RGB frames at fps frames per second of sim time."""

    def __init__(self, path: Path, width_px: int, height_px: int, fps: float) -> None:
        self._ffi, self._lib = _lib.load()
        self._err = self._ffi.new("char[]", ERR_BYTES)
        self.path, self.shape, self.frames = path, (height_px, width_px, 3), 0
        self._v = self._lib.ad_video_open(
            str(path).encode(), width_px, height_px, fps, self._err, ERR_BYTES
        )
        if self._v == self._ffi.NULL:
            raise SimError(self._message())

    def _message(self) -> str:
        return str(self._ffi.string(self._err).decode(errors="replace"))

    def add(self, rgb: npt.NDArray[np.uint8], t_s: float | None = None) -> None:
        """Appends rgb (height x width x 3, rows top-down), stamped with sim time t_s if given."""
        if self._v == self._ffi.NULL:
            raise SimError(f"video {self.path}: closed")
        if rgb.shape != self.shape or rgb.dtype != np.uint8:
            raise ValueError(
                f"video {self.path}: frame {rgb.shape} {rgb.dtype}, expected {self.shape} uint8"
            )
        frame = np.ascontiguousarray(rgb)
        buf = self._ffi.from_buffer("uint8_t[]", frame)
        stamp = -1.0 if t_s is None else t_s
        if self._lib.ad_video_frame(self._v, buf, frame.nbytes, stamp, self._err, ERR_BYTES) != 0:
            raise SimError(self._message())
        self.frames += 1

    def close(self) -> None:
        """Finishes the file (waits for ffmpeg); a second close does nothing."""
        if self._v == self._ffi.NULL:
            return
        v, self._v = self._v, self._ffi.NULL
        if self._lib.ad_video_close(v, self._err, ERR_BYTES) != 0:
            raise SimError(self._message())

    def __enter__(self) -> EpisodeVideo:
        return self

    def __exit__(
        self, t: type[BaseException] | None, e: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()


class RecordEpisodes(gymnasium.Wrapper[Any, Any, Any, Any]):
    """Writes each episode of an env made with render_mode="rgb_array" to
    folder/episode-NNNN.mp4: the frame after reset and after every step, at the env's
    render_fps (its control rate: one frame per step of sim time), stamped with the world's
    sim time."""

    def __init__(self, env: gymnasium.Env[Any, Any], folder: Path) -> None:
        super().__init__(env)
        if env.render_mode != "rgb_array":
            raise ValueError(
                f"RecordEpisodes needs render_mode='rgb_array', not {env.render_mode!r}"
            )
        self.folder, self.episode = folder, -1
        self._video: EpisodeVideo | None = None
        folder.mkdir(parents=True, exist_ok=True)

    def _frame(self) -> None:
        rgb = np.asarray(self.env.render(), dtype=np.uint8)
        if self._video is None:
            fps = float(self.env.metadata.get("render_fps", 20))
            path = self.folder / f"episode-{self.episode:04d}.mp4"
            self._video = EpisodeVideo(path, rgb.shape[1], rgb.shape[0], fps)
        self._video.add(rgb, float(getattr(self.env.unwrapped, "world").time_s))

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        self._finish()
        obs, info = self.env.reset(**kwargs)
        self.episode += 1
        self._frame()
        return obs, info

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        out = self.env.step(action)
        self._frame()
        return out

    def _finish(self) -> None:
        if self._video is not None:
            self._video.close()
            self._video = None

    def close(self) -> None:
        self._finish()
        self.env.close()  # type: ignore[no-untyped-call]  # gymnasium 0.2x: Env.close untyped
