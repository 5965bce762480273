"""The proxy's compiled friction arithmetic (pushctl/episode/actuator_kernels.py) against the
equations it solves, written with numpy's dense algebra. The whole proxy step is checked
against an analytic coasting joint in tests/episode/test_proxy.py."""

from __future__ import annotations

import numpy as np

from pushctl.episode.actuator_kernels import other_impulse, predict_friction, secant_damping

H = 0.01


def _inputs(seed: int) -> dict[str, np.ndarray]:
    """A symmetric positive definite mass matrix and joint vectors of a push's sizes."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((7, 7))
    return {
        "M": 0.1 * A @ A.T + 0.05 * np.eye(7),
        "v": rng.normal(0.0, 0.02, 7),
        "tau": rng.normal(0.0, 5.0, 7),
        "nle": rng.normal(0.0, 5.0, 7),
        "base": 300.0 + rng.uniform(0.0, 1.0, 7),
        "viscous": np.array([0.5] * 4 + [0.2] * 3),
        "coulomb": np.array([1.0] * 4 + [0.5] * 3),
        "impulse": rng.normal(0.0, 0.01, 7),
    }


def _secant(x: dict[str, np.ndarray], v: np.ndarray) -> np.ndarray:
    return x["viscous"] + x["coulomb"] / np.maximum(np.abs(v), 1e-3)


def test_the_prediction_solves_the_steps_joint_equation_with_the_first_secant() -> None:
    for seed in range(20):
        x = _inputs(seed)
        momentum, friction = predict_friction(
            x["M"], x["v"], x["tau"], x["nle"], x["base"], x["viscous"], x["coulomb"],
            1e-3, H, x["impulse"],
        )  # fmt: skip
        expected_momentum = x["M"] @ x["v"] + H * (x["tau"] - x["nle"])
        np.testing.assert_allclose(momentum, expected_momentum, rtol=1e-13, atol=1e-15)
        matrix = x["M"] + np.diag(H * (x["base"] + _secant(x, x["v"])))
        predicted = np.linalg.solve(matrix, expected_momentum + x["impulse"])
        np.testing.assert_allclose(friction, _secant(x, predicted), rtol=1e-9)


def test_the_other_impulse_closes_the_momentum_balance() -> None:
    x = _inputs(3)
    momentum = x["M"] @ x["v"] + H * (x["tau"] - x["nle"])
    damping = x["base"] + _secant(x, x["v"])
    v_new = np.random.default_rng(4).normal(0.0, 0.02, 7)
    r = other_impulse(x["M"], H, damping, v_new, momentum)
    expected = (x["M"] + np.diag(H * damping)) @ v_new - momentum
    np.testing.assert_allclose(r, expected, rtol=1e-12, atol=1e-15)
    # The step that r describes: solving with it gives back v_new.
    again = np.linalg.solve(x["M"] + np.diag(H * damping), momentum + r)
    np.testing.assert_allclose(again, v_new, rtol=1e-9, atol=1e-15)


def test_the_secant_is_linear_below_the_friction_velocity_and_coulomb_above() -> None:
    viscous, coulomb = np.full(4, 0.5), np.full(4, 1.0)
    v = np.array([0.2, -0.2, 5e-4, 0.0])
    d = secant_damping(viscous, coulomb, v, 1e-3)
    np.testing.assert_allclose(d * v, [1.0 + 0.1, -1.0 - 0.1, 0.5 + 2.5e-4, 0.0], rtol=1e-14)
    assert d[3] == 0.5 + 1e3  # at rest: the linear branch's slope F_c / v_s
