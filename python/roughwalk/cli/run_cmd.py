"""``roughwalk run``: plan, optimise and walk a robot to a goal in MuJoCo."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from roughwalk.cli.common import (
    add_output_args,
    info,
    result_envelope,
    simulation_settings,
    write_json,
)

__all__ = ["register", "cmd_run", "ProgressBar", "parse_numbers"]


def parse_numbers(text: str, n: tuple[int, ...], what: str) -> tuple[float, ...]:
    """Comma-separated numbers (``"0.3,0,0"``), as many as one of ``n``."""
    from roughwalk.errors import InvalidArgumentError

    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise InvalidArgumentError(f"{what} must be numbers like 0.3,0,0; got {text!r}") from None
    if len(values) not in n:
        counts = " or ".join(str(k) for k in n)
        raise InvalidArgumentError(f"{what} needs {counts} comma-separated numbers, got {text!r}")
    return values


class ProgressBar:
    """A one-line progress bar on stderr (a line per tenth when stderr is not a terminal)."""

    def __init__(self, label: str = "walking") -> None:
        self.label = label
        self.tty = sys.stderr.isatty()
        self._last = -1

    def __call__(self, sim_time: float, fraction: float, mode: str) -> None:
        """Show ``fraction`` (0–1) of the way done at simulated time ``sim_time`` [s]."""
        width = 30
        filled = int(round(width * fraction))
        bar = "#" * filled + "." * (width - filled)
        line = f"{self.label} [{bar}] {100 * fraction:3.0f}%  t = {sim_time:5.1f} s  {mode:<8}"
        if self.tty:
            print("\r" + line, end="", file=sys.stderr, flush=True)
        elif int(10 * fraction) > self._last:
            self._last = int(10 * fraction)
            print(line, file=sys.stderr, flush=True)

    def close(self) -> None:
        """End the line."""
        if self.tty:
            print(file=sys.stderr, flush=True)


def register(sub: Any) -> None:
    """Add the ``run`` command."""
    p = sub.add_parser(
        "run",
        help="walk a robot from a start to a goal in MuJoCo (plan, optimise, execute)",
        description=(
            "Plans footsteps, optimises each footstep's trajectory while the previous one "
            "executes, and walks the robot in MuJoCo with leg integrators, reflexes and "
            "re-planning (Zucker 2011, §6). Writes the log, result, video, plots and an "
            "index.html into --out-dir."
        ),
    )
    p.add_argument("--robot", default="littledog", help="robot name or MJCF path")
    p.add_argument("--terrain", required=True, help="terrain spec (file, generator, course)")
    p.add_argument("--start", required=True, metavar="X,Y[,YAW]", help="trunk start [m, m, rad]")
    p.add_argument("--goal", required=True, metavar="X,Y", help="goal for the feet's centroid [m]")
    p.add_argument(
        "--planner",
        default="auto",
        choices=("auto", "planner", "crawl"),
        help="footstep planner (auto: the anytime planner if built, else a blind crawl)",
    )
    p.add_argument(
        "--disturb",
        action="append",
        default=[],
        metavar="SPEC",
        help="a disturbance: push:impulse_ns=0.6,at_s=2 | friction:mu=0.4 | "
        "map_error:amplitude_m=0.01,seed=0 (repeatable)",
    )
    p.add_argument("--out-dir", default="run-output", help="folder for everything the run writes")
    p.add_argument("--video", default="video.mp4", help="video file (relative to --out-dir)")
    p.add_argument("--no-video", action="store_true", help="do not render a video")
    p.add_argument("--video-speed", type=float, default=2.0, help="video playback speed")
    add_output_args(p)
    p.set_defaults(func=cmd_run)


def cmd_run(args: argparse.Namespace) -> int:
    """Run, print a summary, write the outputs; exit code 0 on success, 3 on a failed run."""
    from roughwalk.config import configure
    from roughwalk.sim import SimConfig, parse_disturbance, run
    from roughwalk.trajectories import trajectory_config
    from roughwalk.viz.run_outputs import save_run_outputs

    # --set: simulation keys, and trajectory. / footstep. prefixed ones, all
    # checked before the run (as the benches take them).
    sim_sets, trajectory_sets = simulation_settings(args.set)
    cfg = configure(SimConfig(), args.config)
    trajectory = trajectory_config(None, **trajectory_sets) if trajectory_sets else None
    start = parse_numbers(args.start, (2, 3), "--start")
    goal = parse_numbers(args.goal, (2,), "--goal")
    disturbances = [parse_disturbance(s) for s in args.disturb]
    info(f"planning {args.robot} on {args.terrain} from {start} to {goal} ...")
    bar = ProgressBar()
    try:
        result = run(
            args.robot,
            args.terrain,
            start,
            goal,
            planner=args.planner,
            config=cfg,
            trajectory_config=trajectory,
            disturbances=disturbances,
            progress=bar,
            **sim_sets,
        )
    finally:
        bar.close()
    files = save_run_outputs(
        result,
        args.out_dir,
        video=None if args.no_video else args.video,
        video_speed=args.video_speed,
        progress=info,
    )
    o = result.outcome
    status = "reached the goal" if o.success else f"FAILED ({o.reason})"
    print(
        f"{status}: {o.distance_m:.2f} m in {o.time_s:.1f} s = {o.speed_cm_s:.2f} cm/s; "
        f"reflexes {o.reflexes}, re-plans {o.replans}, foot slips {o.foot_slips}, "
        f"waited {o.wait_s:.1f} s"
    )
    if args.json:
        fields = result.to_dict()
        robot, terrain = fields.pop("robot"), fields.pop("terrain")
        write_json(args.json, result_envelope("run", robot=robot, terrain=terrain, **fields))
        info(f"wrote {args.json}")
    info(f"report: {Path(files['index']).resolve()}")
    return 0 if o.success else 3
