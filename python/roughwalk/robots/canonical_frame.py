"""Which leg is which, and the canonical base frame (x forward, y left, z up).

MJCF files disagree on leg names (LF, FL, front_left, RL = rear left, ...),
on the order of the legs and on the axes of the trunk's body frame. Two rules
settle it, in this order:

1. **Names.** When every leg's name says clearly where it is (see
   :func:`leg_label`) and the four labels differ, they are believed: forward is
   the body axis nearest to (front hips − hind hips), left the one nearest to
   (left hips − right hips).
2. **Geometry.** Otherwise up is the body axis nearest to the world's +z at the
   model's default pose, the longitudinal axis is the remaining body axis along
   which the hips spread the most, and its front end is the one facing the
   world's +x at the default pose (models are assumed to spawn facing +x).
   Left follows from up and forward; each leg is then named by the quadrant
   its hip sits in.

The canonical axes are signed body axes, so the rotation ``R_cb`` (body frame
to canonical frame, ``v_c = R_cb v_b``) is a signed permutation matrix.
"""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import RobotModelError

__all__ = ["LEG_NAMES", "leg_label", "canonical_frame"]

LEG_NAMES = ("LF", "RF", "LH", "RH")
"""Canonical leg names, in canonical order: left front, right front, left hind, right hind."""

# Two-letter codes in use: ANYmal's LF/RF/LH/RH, Unitree's FL/FR/RL/RR (RL =
# rear left), and the back/hind variants. "RL" can only mean rear-left: R as
# "right" would leave L with no end to name.
_CODES = {
    "lf": "LF", "fl": "LF",
    "rf": "RF", "fr": "RF",
    "lh": "LH", "hl": "LH", "lb": "LH", "bl": "LH", "rl": "LH", "lr": "LH",
    "rh": "RH", "hr": "RH", "rb": "RH", "br": "RH", "rr": "RH",
}  # fmt: skip
_FRONT_WORDS = ("front", "fore")
_HIND_WORDS = ("hind", "rear", "back")
_SIDE_WORDS = {"left": "L", "right": "R"}


def _tokens(name: str) -> list[str]:
    """Lower-case words of a name split at non-letters and camelCase humps."""
    spaced = re.sub(r"([a-z])([A-Z])", r"\1 \2", name)
    return [t.lower() for t in re.split(r"[^A-Za-z]+", spaced) if t]


def leg_label(name: str) -> str | None:
    """Return the canonical leg name (LF, RF, LH, RH) a body or joint name states, or None.

    Recognises two-letter codes as separate words (``LF_HAA``, ``FL_hip``,
    ``RL_calf``) and spelled-out words (``front_left_hip``, ``rearRight``,
    ``hind_left``). A name that says nothing, or contradicts itself, gives None.
    """
    tokens = _tokens(name)
    codes = {_CODES[t] for t in tokens if t in _CODES}
    if len(codes) == 1:
        return codes.pop()
    if codes:
        return None
    ends = set()
    sides = set()
    for t in tokens:
        if any(w in t for w in _FRONT_WORDS):
            ends.add("F")
        if any(w in t for w in _HIND_WORDS):
            ends.add("H")
        for word, side in _SIDE_WORDS.items():
            if word in t:
                sides.add(side)
    if len(ends) == 1 and len(sides) == 1:
        return sides.pop() + ends.pop()
    return None


def _nearest_axis(v: NDArray[np.float64], exclude: tuple[int, ...] = ()) -> NDArray[np.float64]:
    """Return the signed unit axis nearest in direction to ``v``, skipping ``exclude``."""
    scores = np.abs(v).astype(float)
    scores[list(exclude)] = -1.0
    i = int(np.argmax(scores))
    axis = np.zeros(3)
    axis[i] = 1.0 if v[i] >= 0 else -1.0
    return axis


def canonical_frame(
    hips: NDArray[np.float64],
    names: list[list[str]],
    world_rotation: NDArray[np.float64],
) -> tuple[NDArray[np.float64], list[str], str]:
    """Find the body-to-canonical rotation and each leg's canonical name.

    Parameters
    ----------
    hips:
        (n_legs, 3) hip (first joint anchor) positions in the trunk's body frame [m].
    names:
        For each leg, the names that may say which leg it is, most telling first
        (its first body, its other bodies, its joints).
    world_rotation:
        (3, 3) orientation of the trunk's body frame in the world at the model's
        default pose.

    Returns
    -------
    (R_cb, labels, rule):
        ``R_cb`` (3, 3) maps body-frame vectors to the canonical frame; ``labels``
        gives each input leg's canonical name; ``rule`` is ``"names"`` or
        ``"geometry"``, saying which rule decided.

    """
    labels = [next((lab for n in ns if (lab := leg_label(n))), None) for ns in names]
    if None not in labels and sorted(labels) == sorted(LEG_NAMES):  # type: ignore[type-var]
        hips_of = {lab: hips[i] for i, lab in enumerate(labels)}
        forward = hips_of["LF"] + hips_of["RF"] - hips_of["LH"] - hips_of["RH"]
        leftward = hips_of["LF"] + hips_of["LH"] - hips_of["RF"] - hips_of["RH"]
        x = _nearest_axis(forward)
        y = _nearest_axis(leftward, exclude=(int(np.argmax(np.abs(x))),))
        rotation = np.array([x, y, np.cross(x, y)])
        return rotation, [str(lab) for lab in labels], "names"

    up = _nearest_axis(world_rotation.T @ np.array([0.0, 0.0, 1.0]))
    up_index = int(np.argmax(np.abs(up)))
    spread = np.ptp(hips, axis=0)
    spread[up_index] = -1.0
    long_index = int(np.argmax(spread))
    x = np.zeros(3)
    x[long_index] = 1.0
    if (world_rotation @ x)[0] < 0:
        x = -x
    y = np.cross(up, x)
    rotation = np.array([x, y, up])
    canonical_hips = hips @ rotation.T
    geometric = [("L" if h[1] > 0 else "R") + ("F" if h[0] > 0 else "H") for h in canonical_hips]
    if sorted(geometric) != sorted(LEG_NAMES):
        raise RobotModelError(
            "cannot tell the legs apart: their names do not say which leg is which and "
            f"their hips, at {np.round(canonical_hips, 4).tolist()} m in the canonical frame "
            f"(x forward, y left), are not one per quadrant"
        )
    return rotation, geometric, "geometry"
