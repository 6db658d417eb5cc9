"""The swing settings that were the defaults before session 15: "even" law, heuristic path.

Tests of a timing or path feature that was measured under them pin them,
so that the property they prove does not move with the defaults (now the
"joint" law and path, ramps 0.1 and the lift-off reach).
"""

EVEN_SWINGS = {
    "swing.time_law": "even",
    "swing.path": "cartesian",
    "swing.ramp_fraction": 0.2,
    "swing.lift_off_reach": False,
    "swing.law_trunk": "swing_pose",
}
"""``trajectory_config`` keys: the former swing defaults."""

EVEN_SWING_FIELDS = {k.removeprefix("swing."): v for k, v in EVEN_SWINGS.items()}
"""The same as :class:`~roughwalk.trajectories.config.SwingConfig` fields."""
