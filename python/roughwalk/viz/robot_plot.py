"""Pictures of robots: three orthographic views with the collision model drawn."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from roughwalk.robots import Robot
    from roughwalk.robots.collision_model import CollisionModel

__all__ = ["save_robot_picture", "stadium"]

_LEG_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")


def stadium(p: NDArray[np.float64], q: NDArray[np.float64], r: float, n: int = 24) -> NDArray:
    """Outline (M, 2) of the 2-D projection of a capsule: segment p–q [m] swept by radius r."""
    d = q - p
    length = float(np.hypot(*d))
    ang = float(np.arctan2(d[1], d[0])) if length > 1e-12 else 0.0
    t1 = np.linspace(ang + np.pi / 2, ang + 3 * np.pi / 2, n)
    t2 = np.linspace(ang - np.pi / 2, ang + np.pi / 2, n)
    cap1 = p + r * np.column_stack([np.cos(t1), np.sin(t1)])
    cap2 = q + r * np.column_stack([np.cos(t2), np.sin(t2)])
    return np.vstack([cap1, cap2, cap1[:1]])


def _draw_view(
    ax: Axes,
    robot: Robot,
    model: CollisionModel,
    wa: NDArray,
    wb: NDArray,
    skeleton: list[NDArray],
    axes_idx: tuple[int, int],
    labels: tuple[str, str],
    title: str,
) -> None:
    i, j = axes_idx
    for k in range(len(model)):
        leg = int(model.leg[k])
        colour = "0.45" if leg < 0 else _LEG_COLOURS[leg]
        outline = stadium(wa[k, [i, j]], wb[k, [i, j]], float(model.radius[k]))
        ax.fill(outline[:, 0], outline[:, 1], color=colour, alpha=0.18 if leg < 0 else 0.3, lw=0)
        ax.plot(outline[:, 0], outline[:, 1], color=colour, lw=0.6)
    for leg, chain in enumerate(skeleton):
        ax.plot(chain[:, i], chain[:, j], "-o", color=_LEG_COLOURS[leg], lw=2, ms=3)
    ax.axhline(0.0, color="saddlebrown", lw=1.5) if j == 2 else None
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)


def save_robot_picture(robot: Robot, path: str | Path, model: CollisionModel | None = None) -> None:
    """Save a PNG of ``robot`` in its nominal stance on flat ground: side, front and top views.

    Shaded outlines are the collision model (trunk grey, legs coloured LF/RF/LH/RH),
    lines the kinematic chains base → hip → knee → foot, the brown line the ground.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from roughwalk.robots import reference_fk
    from roughwalk.robots.collision_model import CollisionModel

    cm = model if model is not None else CollisionModel.from_robot(robot)
    q = robot.nominal_q
    base = np.array([0.0, 0.0, robot.nominal_stance.base_height])
    wa, wb = cm.world_segments(robot, q, base)
    qc = robot.to_canonical(q).reshape(4, 3)
    skeleton = []
    for leg, desc in enumerate(robot.leg_descriptions):
        origins, _ = reference_fk.leg_link_frames(desc, qc[leg])
        foot = reference_fk.foot_positions(robot.leg_descriptions, robot.to_canonical(q))[leg]
        skeleton.append(np.vstack([origins, foot]) + base)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8))
    _draw_view(axes[0], robot, cm, wa, wb, skeleton, (0, 2), ("x [m]", "z [m]"), "side (from −y)")
    _draw_view(axes[1], robot, cm, wa, wb, skeleton, (1, 2), ("y [m]", "z [m]"), "front (from +x)")
    axes[1].invert_xaxis()
    _draw_view(axes[2], robot, cm, wa, wb, skeleton, (0, 1), ("x [m]", "y [m]"), "top")
    fig.suptitle(
        f"{robot.name}: nominal stance, base height {base[2]:.3f} m, mass {robot.mass:.2f} kg, "
        f"{len(cm)} collision primitives (legs: LF blue, RF orange, LH green, RH red)",
        fontsize=11,
    )
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
