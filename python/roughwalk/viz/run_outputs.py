"""Everything a finished run leaves in its folder: log, result, video, plots and ``index.html``."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from roughwalk.sim.run import RunResult

__all__ = ["save_run_outputs"]


def save_run_outputs(
    result: RunResult,
    out_dir: str | Path,
    *,
    video: str | Path | None = "video.mp4",
    video_speed: float = 2.0,
    video_size: tuple[int, int] = (640, 480),
    progress: Callable[[str], None] | None = None,
) -> dict[str, Path]:
    """Write a run's files into ``out_dir`` and return them by name.

    Writes the log (``run.npz`` + ``run.json``), ``result.json``, the video
    (``video`` relative to ``out_dir`` unless absolute; None for none; GIF
    when MP4 cannot be written), ``path.png`` and ``tracking.png``, and
    ``index.html`` showing them together. A machine without any headless
    OpenGL gets the page without the video, and a note says why.
    """
    from roughwalk.sim.report import write_report
    from roughwalk.sim.video import VideoUnavailable, render_run
    from roughwalk.terrain import load_terrain
    from roughwalk.viz.run_plot import save_run_path_picture, save_run_tracking_picture

    say = progress or (lambda _m: None)
    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)
    files: dict[str, Path] = dict(result.save(d))
    terrain = load_terrain(result.terrain)
    files["path_picture"] = save_run_path_picture(result.log, terrain, d / "path.png")
    files["tracking_picture"] = save_run_tracking_picture(result.log, d / "tracking.png")
    note: dict[str, Any] = {}
    if video is not None:
        target = Path(video)
        if not target.is_absolute():
            target = d / target
        say(f"rendering the video at {video_speed:g}× speed ...")
        try:
            files["video"] = render_run(
                result.log,
                target,
                speed=video_speed,
                width=video_size[0],
                height=video_size[1],
            )
            result.files["video"] = files["video"].name
        except VideoUnavailable as e:
            note["video"] = f"no video: {e}"
            say(f"note: {note['video']}")
    summary = result.to_dict()
    summary.update(note)
    files["result"].write_text(json.dumps(summary, indent=2) + "\n")
    files["index"] = write_report(
        d,
        summary,
        video=files.get("video"),
        pictures=[files["path_picture"], files["tracking_picture"]],
        events=result.log.events,
        links={
            "result (JSON)": files["result"],
            "run log (JSON)": files["log"],
            "run log arrays (npz)": files["arrays"],
        },
    )
    return files
