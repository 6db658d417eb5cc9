"""Expected ground reaction forces of a footstep.

Zucker 2011, §6: the trajectory carries "which feet should be supporting, and
estimated ground interaction forces".

A static distribution consistent with the cart-table: the vertical loads f_i
of the supporting feet carry m·(g + c̈_z) and put the centre of pressure on
the ZMP (Σf_i·(p_i − zmp) = 0 in x–y); among the loads that do this, the
least-squares (minimum-norm) one. The horizontal force m·c̈_xy is shared in
proportion to the loads. Loads that come out negative (a ZMP outside the
support polygon) are clipped to zero: such a trajectory is not valid anyway.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["static_contact_forces"]


def static_contact_forces(
    feet: ArrayLike,
    support: ArrayLike,
    zmp: ArrayLike,
    com_acceleration: ArrayLike,
    mass: float,
    gravity: float = 9.81,
) -> NDArray[np.float64]:
    """Forces (n, 4, 3) [N] on the feet (n, 4, 3) [m] that are ``support`` (n, 4).

    ``zmp`` (n, 2) [m] and ``com_acceleration`` (n, 3) [m/s²] are the
    trunk's; ``mass`` [kg].
    """
    f = np.asarray(feet, dtype=float)
    s = np.asarray(support, dtype=bool)
    p = np.asarray(zmp, dtype=float)
    acc = np.asarray(com_acceleration, dtype=float)
    n = f.shape[0]
    m = np.zeros((n, 3, 4))
    m[:, 0] = s
    m[:, 1:] = np.swapaxes((f[..., :2] - p[:, None, :]) * s[..., None], 1, 2)
    b = np.zeros((n, 3))
    b[:, 0] = mass * (gravity + acc[:, 2])
    gram = m @ np.swapaxes(m, 1, 2) + 1e-12 * np.eye(3)
    loads = np.einsum("nji,nj->ni", m, np.linalg.solve(gram, b[..., None])[..., 0])
    loads = np.clip(loads, 0.0, None) * s
    total = loads.sum(axis=1, keepdims=True)
    share = np.divide(loads, total, out=np.zeros_like(loads), where=total > 0)
    out = np.zeros((n, 4, 3))
    out[..., 2] = loads
    out[..., :2] = mass * acc[:, None, :2] * share[..., None]
    return out
