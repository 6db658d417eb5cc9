"""Desired states shared by the simulation-controller tests."""

from __future__ import annotations

import numpy as np

import roughwalk
from roughwalk.sim.recovery import pose_segment


def standing_step(
    robot: roughwalk.Robot,
    angles: tuple[float, float, float] = (0, 0, 0),
    in_contact: tuple[bool, bool, bool, bool] = (True, True, True, True),
    kind: str = "step",
) -> object:
    """The desired state of a footstep that stands still in the nominal stance on flat ground.

    ``angles``: the trunk's orientation, as :func:`pose_segment` takes it [rad];
    ``in_contact``: which feet (LF, RF, LH, RH) bear the trunk; ``kind``: the segment's.
    """
    st = robot.nominal_stance
    base = np.array([0.5, 0.0, st.base_height])
    feet = st.feet + base
    segment = pose_segment(
        robot,
        np.array([base, base]),
        np.array([angles, angles], dtype=float),
        np.array([feet, feet]),
        np.array(in_contact, dtype=bool),
        1.0,
        kind,
        0.0,
    )
    return segment.sample(0.0)
