"""A run's static ``index.html``: the video, the plots and the numbers on one page.

The page links files that sit beside it in the output folder (video,
pictures, log), so the folder can be copied or served as it is.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

__all__ = ["write_report"]

_ROWS = (
    ("success", "success", ""),
    ("reason", "reason", ""),
    ("distance_m", "distance (start centroid → goal)", "m"),
    ("time_s", "time (first motion → goal)", "s"),
    ("speed_cm_s", "average speed", "cm/s"),
    ("reflexes", "reflexes", ""),
    ("replans", "re-plans", ""),
    ("relaxed_plans", "plans without the edge margin", ""),
    ("foot_slips", "foot slips", ""),
    ("wait_s", "waiting for optimisation", "s"),
    ("replan_s", "standing while re-planning", "s"),
    ("steps", "footsteps executed", ""),
    ("max_roll_rad", "largest roll", "rad"),
    ("max_pitch_rad", "largest pitch", "rad"),
    ("final_distance_m", "final distance to goal", "m"),
    ("shin_contacts", "legs touching the terrain above the foot", "ticks"),
    ("self_contacts", "robot touching itself", "ticks"),
)


def _fmt(value: Any) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "—" if not math.isfinite(value) else f"{value:.3g}"
    if value is None:
        return "—"
    return str(value)


def write_report(
    out_dir: str | Path,
    result: Mapping[str, Any],
    *,
    video: str | Path | None = None,
    pictures: Sequence[str | Path] = (),
    events: Sequence[Mapping[str, Any]] = (),
    title: str | None = None,
    links: Mapping[str, str | Path] | None = None,
) -> Path:
    """Write ``out_dir/index.html`` for a run; returns its path.

    Parameters
    ----------
    result:
        The run's JSON fields (:meth:`RunResult.to_dict`).
    video:
        The video file (MP4 shown with ``<video>``, GIF with ``<img>``).
    pictures:
        PNG files to show, in order.
    events:
        The log's events (reflexes, re-plans, pushes...) for a table.
    links:
        Other files to link by label (the log, the JSON result).
    """
    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)

    def rel(p: str | Path) -> str:
        path = Path(p)
        try:
            return html.escape(path.resolve().relative_to(d.resolve()).as_posix())
        except ValueError:
            return html.escape(path.as_posix())

    name = title or f"{result.get('robot', 'robot')} on {result.get('terrain', 'terrain')}"
    ok = bool(result.get("success"))
    parts = [
        "<!doctype html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(name)}</title>",
        "<style>body{font-family:system-ui,sans-serif;max-width:1000px;margin:2em auto;"
        "padding:0 1em;color:#222}table{border-collapse:collapse}td,th{padding:.25em .8em;"
        "border-bottom:1px solid #ddd;text-align:left}.ok{color:#17803d}.fail{color:#b3261e}"
        "img,video{max-width:100%;border:1px solid #ccc;margin:.5em 0}</style>",
        "</head><body>",
        f"<h1>{html.escape(name)}</h1>",
        f'<p class="{"ok" if ok else "fail"}"><strong>'
        f"{'Reached the goal' if ok else 'Failed'}</strong>: "
        f"{html.escape(str(result.get('reason', '')))}</p>",
    ]
    if video is not None:
        v = rel(video)
        if str(video).lower().endswith(".mp4"):
            parts.append(f'<video src="{v}" controls autoplay muted loop playsinline></video>')
        else:
            parts.append(f'<img src="{v}" alt="video of the run">')
    parts.append("<h2>Numbers</h2><table>")
    for key, label, unit in _ROWS:
        if key in result:
            value = _fmt(result[key])
            parts.append(
                f"<tr><th>{html.escape(label)}</th><td>{html.escape(value)}"
                f"{' ' + unit if unit and value != '—' else ''}</td></tr>"
            )
    for key in ("start", "goal", "planner"):
        if key in result:
            parts.append(f"<tr><th>{key}</th><td>{html.escape(_fmt(result[key]))}</td></tr>")
    split = (result.get("extra") or {}).get("time_breakdown")
    if split and split.get("footsteps"):
        text = (
            f"shifts {split['shift_s']:.1f} s, swings {split['swing_s']:.1f} s, "
            f"stretched {split.get('stretch_s', 0.0):.1f} s, "
            f"settling {split['settle_s']:.1f} s, waits {split['wait_s']:.1f} s, "
            f"lift-off holds {split.get('gate_s', 0.0):.1f} s, "
            f"reflexes {split['reflex_s']:.1f} s, re-plans {split.get('replan_s', 0.0):.1f} s; "
            f"{split['footsteps']} footsteps, "
            f"mean stride {100 * split['mean_stride_m']:.1f} cm"
        )
        parts.append(f"<tr><th>where the time went</th><td>{html.escape(text)}</td></tr>")
    disturbances = result.get("disturbances") or []
    if disturbances:
        text = "; ".join(str(x) for x in disturbances)
        parts.append(f"<tr><th>disturbances</th><td>{html.escape(text)}</td></tr>")
    parts.append("</table>")
    for p in pictures:
        parts.append(f'<p><img src="{rel(p)}" alt="{html.escape(Path(p).stem)}"></p>')
    shown = [
        e
        for e in events
        if e.get("kind")
        in (
            "reflex",
            "replan",
            "recentre",
            "lift_gate",
            "push",
            "friction",
            "fall",
            "goal",
            "plan",
            "end",
        )
    ]
    if shown:
        parts.append("<h2>Events</h2><table><tr><th>t [s]</th><th>event</th><th>detail</th></tr>")
        for e in shown:
            detail = e.get("detail") or e.get("reason") or e.get("status") or ""
            parts.append(
                f"<tr><td>{e['time']:.2f}</td><td>{html.escape(str(e['kind']))}</td>"
                f"<td>{html.escape(str(detail))}</td></tr>"
            )
        parts.append("</table>")
    if links:
        parts.append("<h2>Files</h2><ul>")
        for label, p in links.items():
            parts.append(f'<li><a href="{rel(p)}">{html.escape(label)}</a></li>')
        parts.append("</ul>")
    parts.append("</body></html>")
    index = d / "index.html"
    index.write_text("\n".join(parts) + "\n")
    return index
