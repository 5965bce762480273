"""The stick rule (``WorldConfig.stick_fraction``, off by default): a sliding support point
whose along-row friction impulse comes out inside its bound gets the rest box
(``pushctl.contact.compiled.assembly.refine_slip``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pushctl.contact.compiled.assembly import refine_slip
from pushctl.contact.world import STICK_FRACTION, World, WorldConfig
from pushctl.errors import ConfigError
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig

H, LIMIT = 0.01, 2.0  # [s], [N]: the point's bound is H * LIMIT [N·s]


def _refined(along_impulse: float, velocity: tuple[float, float], fraction: float):
    """One support point at the object's origin, sliding along +x, after a step whose object
    velocity is ``velocity`` (vx, vy) and whose along-row impulse is ``along_impulse``
    [N·s] (the two ground rows are the impulses' last two): (changed, sliding, direction)."""
    directions, sliding = np.array([[1.0, 0.0]]), np.array([True])
    p = np.array([0.3, 0.0, along_impulse, 0.0])  # a prong row pair, then the ground pair
    changed = refine_slip(
        np.zeros(3), np.array([*velocity, 0.0]), np.zeros((1, 2)), directions, sliding,
        np.cos(np.radians(5.0)), p, np.array([LIMIT]), H, fraction,
    )  # fmt: skip
    return changed, bool(sliding[0]), directions[0]


def test_a_sliding_point_whose_friction_is_inside_its_bound_sticks() -> None:
    bound = H * LIMIT
    # inside the bound and moving along the box: it sticks, and the step is solved again
    assert _refined(-0.5 * bound, (0.01, 0.0), STICK_FRACTION)[:2] == (True, False)
    # off (the default): the same point is settled, sliding
    assert _refined(-0.5 * bound, (0.01, 0.0), 0.0)[:2] == (False, True)
    # at its bound and off by 90 degrees: the box turns half-way, still sliding
    changed, sliding, direction = _refined(-bound, (0.0, 0.01), STICK_FRACTION)
    assert changed and sliding
    np.testing.assert_allclose(direction, np.array([1.0, 1.0]) / np.sqrt(2.0))
    # at its bound and aligned: settled
    assert _refined(-bound, (0.01, 0.0), STICK_FRACTION)[:2] == (False, True)
    # inside but stopped: its solution already meets the rest box, left alone
    assert _refined(-0.5 * bound, (0.0, 0.0), STICK_FRACTION)[:2] == (False, True)


def test_the_fraction_is_checked() -> None:
    assert WorldConfig().stick_fraction == 0.0
    assert WorldConfig(stick_fraction=0).stick_fraction == 0.0
    for bad in (1.0, -0.1, True, float("nan"), "0.5"):
        with pytest.raises(ConfigError, match="stick_fraction must be a number in"):
            WorldConfig(stick_fraction=bad)  # type: ignore[arg-type]


def _zero_residual_push_counts(monkeypatch, fraction: float) -> tuple[int, int, int]:
    """(solves, re-solves, steps that kept their first solution) of the zero-residual
    ``Push-v0`` push of ``reset(seed=2)`` (wedge, constant), approach included, its worlds
    built with ``stick_fraction`` = ``fraction``."""
    build = World.__init__

    def with_fraction(self, *args, **kwargs) -> None:
        build(self, *args, **kwargs)
        self.config = replace(self.config, stick_fraction=fraction)

    monkeypatch.setattr(World, "__init__", with_fraction)
    env = PushEnv(EnvConfig())
    env.reset(seed=2)
    done = False
    while not done:
        *_, terminated, truncated, _ = env.step(np.zeros(3, dtype=np.float32))
        done = terminated or truncated
    assert env.episode is not None
    stats = env.episode.world.stats
    return stats.solves, stats.slip_iterations, stats.slip_unsettled


def test_the_rule_halves_a_zero_residual_push_s_solves_as_measured(monkeypatch) -> None:
    """The counts measured on the branch the rule was first made on
    (docs/reproducibility-and-speed.md), which did not survive: this rebuild is that rule."""
    assert _zero_residual_push_counts(monkeypatch, 0.0) == (6139, 3499, 581)
    assert _zero_residual_push_counts(monkeypatch, STICK_FRACTION) == (3049, 409, 36)
