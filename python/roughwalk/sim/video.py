"""Videos of runs: MuJoCo's offscreen renderer, a camera that follows the robot, MP4 or GIF.

Rendering needs an OpenGL context without a display: EGL (Mesa's
``libegl1``/``libegl-mesa0`` on Debian; GPU drivers too) or OSMesa
(``libosmesa6``). ``MUJOCO_GL=egl|osmesa`` picks one; by default EGL is
tried first, then OSMesa. The context is made here with MuJoCo's own
``mujoco.egl``/``mujoco.osmesa`` helpers, so it works whatever was imported
before. Without either, :class:`VideoUnavailable` says what to install.

MP4 (H.264) is written with the ffmpeg binary that the ``imageio-ffmpeg``
wheel ships; without it the video is an animated GIF (Pillow).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError, RoughwalkError

if TYPE_CHECKING:
    from roughwalk.sim.run_log import RunLog
    from roughwalk.sim.world import World

__all__ = [
    "VideoUnavailable",
    "OffscreenRenderer",
    "render_run",
    "write_video",
    "mp4_available",
    "gl_backend",
]


class VideoUnavailable(RoughwalkError):
    """No headless OpenGL backend (EGL or OSMesa) could be started."""


def mp4_available() -> bool:
    """Whether MP4 can be written (the ``imageio-ffmpeg`` wheel and its ffmpeg)."""
    try:
        import imageio_ffmpeg

        return Path(imageio_ffmpeg.get_ffmpeg_exe()).is_file()
    except (ImportError, RuntimeError, OSError):
        return False


def _make_context(width: int, height: int) -> tuple[Any, str]:
    """A current offscreen GL context, trying MUJOCO_GL's choice or EGL, then OSMesa."""
    wanted = os.environ.get("MUJOCO_GL", "").lower()
    order = [wanted] if wanted in ("egl", "osmesa") else ["egl", "osmesa"]
    errors = []
    for backend in order:
        # PyOpenGL reads its platform once, on first import.
        os.environ.setdefault("PYOPENGL_PLATFORM", backend)
        try:
            if backend == "egl":
                from mujoco.egl import GLContext
            else:
                from mujoco.osmesa import GLContext
            ctx = GLContext(width, height)
            ctx.make_current()
            return ctx, backend
        except Exception as e:  # noqa: BLE001 - any failure means "try the next backend"
            errors.append(f"{backend}: {type(e).__name__}: {e}")
    raise VideoUnavailable(
        "no headless OpenGL backend could start ("
        + "; ".join(errors)
        + "); install Debian's libegl1 and libegl-mesa0 (EGL) or libosmesa6 (OSMesa), "
        "or set MUJOCO_GL=egl|osmesa"
    )


def gl_backend() -> str | None:
    """The backend a renderer would use ("egl", "osmesa"), or None when none starts."""
    try:
        ctx, backend = _make_context(16, 16)
    except VideoUnavailable:
        return None
    ctx.free()
    return backend


class OffscreenRenderer:
    """Renders a world's model from a camera that follows a point.

    Parameters
    ----------
    model:
        The compiled model (its ``offwidth``/``offheight`` bound the size).
    width, height:
        Image size [px].
    distance:
        Camera distance from the followed point [m].
    azimuth, elevation:
        Camera direction [deg] (MuJoCo's convention: azimuth about z from +x,
        elevation negative looking down).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        width: int = 640,
        height: int = 480,
        distance: float = 0.8,
        azimuth: float = 120.0,
        elevation: float = -25.0,
    ) -> None:
        self.model = model
        self.width, self.height = int(width), int(height)
        w = min(self.width, int(model.vis.global_.offwidth))
        h = min(self.height, int(model.vis.global_.offheight))
        if (w, h) != (self.width, self.height):
            raise InvalidArgumentError(
                f"video size {self.width}×{self.height} exceeds the model's offscreen buffer "
                f"{model.vis.global_.offwidth}×{model.vis.global_.offheight}"
            )
        self._ctx, self.backend = _make_context(self.width, self.height)
        self._con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._con)
        self._scene = mujoco.MjvScene(model, maxgeom=4000)
        self._option = mujoco.MjvOption()
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.camera.distance = distance
        self.camera.azimuth = azimuth
        self.camera.elevation = elevation
        self._rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._pixels = np.zeros((self.height, self.width, 3), dtype=np.uint8)

    def render(
        self, data: mujoco.MjData, lookat: NDArray[np.float64], text: str = ""
    ) -> NDArray[np.uint8]:
        """One RGB frame (height, width, 3) of ``data`` looking at ``lookat`` [m]."""
        self._ctx.make_current()
        self.camera.lookat[:] = lookat
        mujoco.mjv_updateScene(
            self.model,
            data,
            self._option,
            None,
            self.camera,
            mujoco.mjtCatBit.mjCAT_ALL,
            self._scene,
        )
        mujoco.mjr_render(self._rect, self._scene, self._con)
        if text:
            mujoco.mjr_overlay(
                mujoco.mjtFont.mjFONT_NORMAL,
                mujoco.mjtGridPos.mjGRID_TOPLEFT,
                self._rect,
                text,
                "",
                self._con,
            )
        mujoco.mjr_readPixels(self._pixels, None, self._rect, self._con)
        return np.flipud(self._pixels).copy()

    def close(self) -> None:
        """Free the GL context."""
        if self._ctx is not None:
            self._con.free()
            self._ctx.free()
            self._ctx = None

    def __enter__(self) -> OffscreenRenderer:
        """Use as a context manager."""
        return self

    def __exit__(self, *exc: object) -> None:
        """Free the context."""
        self.close()


def write_video(frames: Iterator[NDArray[np.uint8]], path: str | Path, fps: float) -> Path:
    """Write RGB frames to ``path``: MP4 when the suffix is .mp4 and ffmpeg is there, else GIF.

    Returns the path written (its suffix is .gif when MP4 was not possible).
    """
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    if p.suffix.lower() == ".mp4" and mp4_available():
        import imageio_ffmpeg

        first = next(frames)
        h, w = first.shape[:2]
        writer = imageio_ffmpeg.write_frames(
            str(p),
            (w, h),
            fps=fps,
            codec="libx264",
            pix_fmt_out="yuv420p",
            macro_block_size=1,
            ffmpeg_log_level="error",
            output_params=["-crf", "23"],
        )
        writer.send(None)
        writer.send(np.ascontiguousarray(first))
        for frame in frames:
            writer.send(np.ascontiguousarray(frame))
        writer.close()
        return p
    from PIL import Image

    gif = p.with_suffix(".gif")
    images = [Image.fromarray(f) for f in frames]
    if not images:
        raise InvalidArgumentError("no frames to write")
    images[0].save(
        gif,
        save_all=True,
        append_images=images[1:],
        duration=int(round(1000.0 / fps)),
        loop=0,
        optimize=False,
    )
    return gif


def render_run(
    log: RunLog,
    path: str | Path,
    *,
    world: World | None = None,
    fps: float = 30.0,
    width: int = 640,
    height: int = 480,
    speed: float = 1.0,
    distance: float | None = None,
    shadows: bool = False,
) -> Path:
    """Render a run's log to a video file following the robot; returns the path written.

    Parameters
    ----------
    log:
        The run (its ``qpos`` at the control rate).
    path:
        Output file (.mp4, or .gif).
    world:
        The world to draw in; rebuilt from the log's robot and terrain by default.
    fps:
        Frames per second of the video.
    speed:
        Playback speed (2 = twice real time).
    distance:
        Camera distance [m]; by default four times the robot's nominal height.
    shadows:
        Cast shadows (about 2.5× slower with a software renderer).
    """
    if world is None:
        from roughwalk.robots import load_robot
        from roughwalk.sim.world import World
        from roughwalk.terrain import load_terrain

        meta = log.meta
        try:
            robot, terrain = meta["robot"], meta["terrain"]
        except KeyError as e:
            raise InvalidArgumentError(f"the run log names no {e.args[0]}") from None
        world = World(load_robot(robot), load_terrain(terrain))
    model = world.model
    cast = model.light_castshadow.copy()
    model.light_castshadow[:] = cast & shadows
    data = mujoco.MjData(model)
    times = np.asarray(log["time"], dtype=float)
    qpos = np.asarray(log["qpos"], dtype=float)
    if len(times) == 0:
        raise InvalidArgumentError("the run log has no states to render")
    if qpos.shape[1] != model.nq:
        raise InvalidArgumentError(
            f"the log's qpos has {qpos.shape[1]} values; the model has nq = {model.nq}"
        )
    modes = np.asarray(log.arrays.get("mode", np.zeros(len(times))), dtype=int)
    from roughwalk.sim.run_log import MODES

    robot_height = world.robot.nominal_stance.base_height
    cam_distance = distance if distance is not None else max(4.0 * robot_height, 0.5)
    frame_times = np.arange(times[0], times[-1] + 1e-9, speed / fps)
    index = np.clip(np.searchsorted(times, frame_times), 0, len(times) - 1)
    base = np.asarray(log["base_pos"], dtype=float) if "base_pos" in log.arrays else qpos[:, :3]

    with OffscreenRenderer(model, width, height, distance=cam_distance) as renderer:

        def frames() -> Iterator[NDArray[np.uint8]]:
            lookat = base[index[0]].copy()
            for t, k in zip(frame_times, index, strict=True):
                data.qpos[:] = qpos[k]
                mujoco.mj_forward(model, data)
                # A lagging camera: smooth, and ignores the trunk's bobbing.
                lookat += 0.15 * (base[k] - lookat)
                mode = MODES[modes[k]] if 0 <= modes[k] < len(MODES) else ""
                yield renderer.render(data, lookat, f"t = {t:5.1f} s  {mode}")

        try:
            return write_video(frames(), path, fps)
        finally:
            model.light_castshadow[:] = cast
