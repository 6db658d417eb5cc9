"""A video of a tracked motion: the logged ``qpos`` replayed with MuJoCo's offscreen renderer."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.sim.video import OffscreenRenderer, write_video

if TYPE_CHECKING:
    from roughwalk.sim.world import World
    from roughwalk.tracking.outcome import TrackingLog

__all__ = ["render_tracking"]


def render_tracking(
    world: World,
    log: TrackingLog,
    path: str | Path,
    *,
    fps: float = 30.0,
    width: int = 640,
    height: int = 480,
) -> Path:
    """Render ``log`` in ``world`` to ``path`` (.mp4, or .gif without ffmpeg); returns the path."""
    model = world.model
    data = mujoco.MjData(model)
    times = np.asarray(log.t)
    frame_times = np.arange(times[0], times[-1] + 1e-9, 1.0 / fps)
    index = np.clip(np.searchsorted(times, frame_times), 0, len(times) - 1)
    distance = max(4.0 * world.robot.nominal_stance.base_height, 0.5)
    cast = model.light_castshadow.copy()
    model.light_castshadow[:] = 0
    with OffscreenRenderer(model, width, height, distance=distance) as renderer:

        def frames() -> Iterator[NDArray[np.uint8]]:
            lookat = log.base_pos[index[0]].copy()
            for t, k in zip(frame_times, index, strict=True):
                data.qpos[:] = log.qpos[k]
                mujoco.mj_forward(model, data)
                lookat += 0.15 * (log.base_pos[k] - lookat)
                yield renderer.render(data, lookat, f"t = {t:5.2f} s")

        try:
            return write_video(frames(), path, fps)
        finally:
            model.light_castshadow[:] = cast
