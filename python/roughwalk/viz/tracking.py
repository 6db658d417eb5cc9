"""Pictures of a tracked motion, like Melon et al. 2020's Figure 4.

Left column: the x, y and z contact forces of the feet, planned (dashed)
against measured (solid). Right column: the base's angular velocities,
planned against measured, then the base position and orientation tracking
errors over time.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from roughwalk.tracking.outcome import TrackingOutcome

__all__ = ["save_tracking_picture"]

_LEG_NAMES = ("LF", "RF", "LH", "RH")
_LEG_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
_AXES = ("x", "y", "z")


def save_tracking_picture(outcome: TrackingOutcome, path: str | Path, title: str = "") -> Path:
    """Draw ``outcome``'s log to the PNG ``path``; return the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    log = outcome.log
    if log is None:
        from roughwalk.errors import InvalidArgumentError

        raise InvalidArgumentError("this tracking outcome kept no log to draw")
    t = log.t
    fig, axes = plt.subplots(3, 2, figsize=(12, 9), sharex=True)
    for k in range(3):
        ax = axes[k, 0]
        for leg in range(4):
            c = _LEG_COLOURS[leg]
            ax.plot(t, log.forces[:, leg, k], color=c, lw=1.0, label=f"{_LEG_NAMES[leg]}")
            ax.plot(t, log.forces_ref[:, leg, k], color=c, lw=1.0, ls="--")
        ax.set_ylabel(f"f_{_AXES[k]} [N]")
    axes[0, 0].legend(ncol=4, fontsize=8, title="measured (—), planned (- -)", title_fontsize=8)
    ax = axes[0, 1]
    for k, c in enumerate(("tab:blue", "tab:orange", "tab:green")):
        ax.plot(t, log.base_angvel[:, k], color=c, lw=1.0, label=f"ω_{_AXES[k]}")
        ax.plot(t, log.base_angvel_ref[:, k], color=c, lw=1.0, ls="--")
    ax.set_ylabel("base ω [rad/s]")
    ax.legend(ncol=3, fontsize=8)
    ax = axes[1, 1]
    err = log.base_pos - log.base_pos_ref
    for k, c in enumerate(("tab:blue", "tab:orange", "tab:green")):
        ax.plot(t, 100 * err[:, k], color=c, lw=1.0, label=f"e_{_AXES[k]}")
    ax.plot(t, 100 * np.linalg.norm(err, axis=1), color="k", lw=1.2, label="‖e‖")
    ax.set_ylabel("base position error [cm]")
    ax.legend(ncol=4, fontsize=8)
    ax = axes[2, 1]
    for k, (c, name) in enumerate(
        zip(("tab:blue", "tab:orange", "tab:green"), ("roll", "pitch", "yaw"), strict=True)
    ):
        ax.plot(t, np.degrees(log.orientation_error[:, k]), color=c, lw=1.0, label=name)
    ax.set_ylabel("base orientation error [deg]")
    ax.legend(ncol=3, fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    end = outcome.duration_s
    for ax in axes.ravel():
        ax.axvline(end, color="0.6", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
    verdict = "success" if outcome.success else "failure"
    headline = f"{title + ': ' if title else ''}{verdict} — {outcome.reason}"
    implied = outcome.implied_torque
    if implied is not None:
        # Where the plan's own forces ask the most of a joint: a dotted line and its figure.
        limit = implied["limit_nm"]
        headline += (
            f"\nthe plan's forces ask up to {implied['max_nm']:.3g} N·m of {implied['joint']}"
            f"{'' if limit is None else f' (limit {limit:.3g})'} at {implied['time_s']:.2f} s"
            f" (· · ·); over a limit on {100 * implied['over_limit_fraction']:.0f} % of the plan"
        )
        for ax in axes.ravel():
            ax.axvline(implied["time_s"], color="tab:red", lw=0.8, ls=":")
    fig.suptitle(headline, fontsize=10)
    fig.tight_layout()
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(p, dpi=110)
    plt.close(fig)
    return p
