"""The actor's forward pass over a batch of observations, each row's bits independent of the
batch: row i of a forward over B observations equals a forward over that one observation.

A BLAS matrix product does not promise that (its blocking, and so its order of summation,
changes with the number of rows, and a single row goes to a matrix-vector kernel), and the
training collectors need it: the episodes of a round are stepped together, as many per
collector as the round has over the collectors, and an episode must be the same whatever
that number is (:mod:`pushctl.rl.train`). So each dense layer is a compiled loop that
computes every output as ``b_j + Σ_k x_k·W_jk`` summed in k order, one row at a time; it
vectorises over the outputs j (the weights stored transposed, (K, J)), which reorders no
sum. The output's tanh is a scalar libm call per element (numba without SVML, as here:
``numba.config.USING_SVML`` is checked) for the same reason.
"""

from __future__ import annotations

import numba
import numpy as np

if numba.config.USING_SVML:  # type: ignore[attr-defined]  # pragma: no cover - SVML would vectorise tanh by batch size
    raise ImportError("pushctl.rl.batched_actor needs numba without SVML (row-exact tanh)")


@numba.njit(cache=True, nogil=True)
def dense(x: np.ndarray, weight_t: np.ndarray, bias: np.ndarray, activation: int) -> np.ndarray:
    """One layer: x (B, K) float32, weight_t (K, J) float32 (the layer's weight transposed),
    bias (J,) float32 → (B, J) float32; ``activation`` 0 none, 1 ReLU, 2 tanh."""
    rows, inputs = x.shape
    outputs = bias.shape[0]
    out = np.empty((rows, outputs), dtype=np.float32)
    for r in range(rows):
        acc = bias.copy()
        for k in range(inputs):
            xk = x[r, k]
            for j in range(outputs):
                acc[j] += xk * weight_t[k, j]
        for j in range(outputs):
            value = acc[j]
            if activation == 1:
                value = max(value, np.float32(0.0))
            elif activation == 2:
                value = np.float32(np.tanh(np.float64(value)))
            out[r, j] = value
    return out


def forward(x: np.ndarray, layers: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """The MLP of ``layers`` ((K, J) transposed weight, (J,) bias, float32 each): ReLU on the
    hidden layers, tanh on the output. x (B, K0) float32 → (B, J_last) float32."""
    last = len(layers) - 1
    for i, (weight_t, bias) in enumerate(layers):
        x = dense(x, weight_t, bias, 2 if i == last else 1)
    return x
