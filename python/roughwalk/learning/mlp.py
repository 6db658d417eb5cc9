"""A multilayer perceptron as plain arrays: weights, biases and the input/output scaling.

The network is trained by scikit-learn's ``MLPRegressor`` (see
:mod:`roughwalk.learning.training`) but evaluated here with numpy alone, so
that a model file holds numbers only and survives library upgrades.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["MLP", "ACTIVATIONS"]

ACTIVATIONS = ("tanh", "relu")


@dataclass(frozen=True)
class MLP:
    """y = out_mean + out_scale ⊙ f(x) with f a feed-forward network on standardised x.

    Attributes
    ----------
    weights, biases:
        Per layer (n_in, n_out) and (n_out,); hidden layers use ``activation``,
        the last is linear.
    activation:
        "tanh" or "relu".
    in_mean, in_scale:
        Input standardisation: x̂ = (x − in_mean) / in_scale.
    out_mean, out_scale:
        Output de-standardisation.

    """

    weights: tuple[NDArray[np.float32], ...]
    biases: tuple[NDArray[np.float32], ...]
    activation: str
    in_mean: NDArray[np.float64]
    in_scale: NDArray[np.float64]
    out_mean: NDArray[np.float64]
    out_scale: NDArray[np.float64]

    def __post_init__(self) -> None:
        if self.activation not in ACTIVATIONS:
            raise InvalidArgumentError(
                f"unknown activation {self.activation!r}; known: {', '.join(ACTIVATIONS)}"
            )
        if len(self.weights) != len(self.biases) or not self.weights:
            raise InvalidArgumentError(
                f"an MLP needs as many biases as weights (≥ 1), got "
                f"{len(self.weights)} and {len(self.biases)}"
            )

    @property
    def n_inputs(self) -> int:
        """Input size."""
        return int(self.weights[0].shape[0])

    @property
    def n_outputs(self) -> int:
        """Output size."""
        return int(self.weights[-1].shape[1])

    @property
    def hidden_layers(self) -> tuple[int, ...]:
        """Sizes of the hidden layers."""
        return tuple(int(w.shape[1]) for w in self.weights[:-1])

    def __call__(self, inputs: ArrayLike) -> NDArray[np.float64]:
        """Outputs (n, n_outputs) for inputs (n, n_inputs) (or one input (n_inputs,))."""
        x = np.asarray(inputs, dtype=float)
        single = x.ndim == 1
        x = np.atleast_2d(x)
        if x.shape[1] != self.n_inputs:
            raise InvalidArgumentError(f"the MLP takes {self.n_inputs} inputs, got {x.shape[1]}")
        h = (x - self.in_mean) / self.in_scale
        last = len(self.weights) - 1
        for k, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            h = h @ w.astype(float) + b.astype(float)
            if k < last:
                h = np.tanh(h) if self.activation == "tanh" else np.maximum(h, 0.0)
        y = self.out_mean + h * self.out_scale
        return y[0] if single else y

    def arrays(self) -> dict[str, NDArray[np.float64] | NDArray[np.float32]]:
        """The arrays to store, by name."""
        out: dict[str, NDArray[np.float64] | NDArray[np.float32]] = {
            "in_mean": self.in_mean,
            "in_scale": self.in_scale,
            "out_mean": self.out_mean,
            "out_scale": self.out_scale,
        }
        for k, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            out[f"w{k}"] = w
            out[f"b{k}"] = b
        return out

    @classmethod
    def from_arrays(
        cls, arrays: dict[str, NDArray[np.float64]], activation: str, n_layers: int
    ) -> MLP:
        """The MLP stored by :meth:`arrays`."""
        try:
            return cls(
                tuple(np.asarray(arrays[f"w{k}"], dtype=np.float32) for k in range(n_layers)),
                tuple(np.asarray(arrays[f"b{k}"], dtype=np.float32) for k in range(n_layers)),
                activation,
                np.asarray(arrays["in_mean"], dtype=float),
                np.asarray(arrays["in_scale"], dtype=float),
                np.asarray(arrays["out_mean"], dtype=float),
                np.asarray(arrays["out_scale"], dtype=float),
            )
        except KeyError as e:
            raise InvalidArgumentError(f"MLP arrays lack {e}") from None
