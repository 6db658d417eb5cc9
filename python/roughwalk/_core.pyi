"""Type stubs for the compiled module ``roughwalk._core`` (the Rust core's bindings)."""

import numpy as np
from numpy.typing import NDArray

__version__: str

class HeightField:
    """A regular-grid height field held in Rust (x-major heights [m])."""

    def __init__(
        self,
        x0: float,
        y0: float,
        dx: float,
        dy: float,
        heights: NDArray[np.float64],
        known: NDArray[np.bool_] | None = None,
    ) -> None: ...
    def height(
        self, xy: NDArray[np.float64], interpolation: str = "bilinear"
    ) -> NDArray[np.float64]: ...
    def height_and_gradient(
        self, xy: NDArray[np.float64], interpolation: str = "bilinear"
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
    def is_known(self, xy: NDArray[np.float64]) -> NDArray[np.bool_]: ...
    @property
    def shape(self) -> tuple[int, int]: ...

# ---- sdf (crates/roughwalk-py/src/sdf.rs) ----

# ---- robot kinematics (crates/roughwalk-py/src/robot.rs) ----
