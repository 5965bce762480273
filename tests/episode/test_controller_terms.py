"""A mounted pusher's controller terms come from the world's pass
(:class:`pushctl.arm.BelievedTerms`) instead of a second pass of the controller's own model:
every push must be the same to the bit as with the second pass."""

from __future__ import annotations

from dataclasses import fields

import numpy as np
import pytest

from pushctl.episode.draw import draw_planned_scenario
from pushctl.episode.proxy import effects_for
from pushctl.episode.runner import Episode


def _second_pass(episode: Episode):
    """The controller's terms as Episode computed them before: its own model's whole pass."""
    world = episode.world
    if episode.controller_arm is world.arm:
        return world.arm_terms
    return episode.controller_arm.compute(world.q, world.v)


def _trace_bytes(trace) -> dict[str, bytes]:
    return {
        item.name: np.asarray(getattr(trace, item.name)).tobytes()
        for item in fields(trace)
        if getattr(trace, item.name) is not None
    }


def _push(scenario, plan, plant: str, residuals: np.ndarray) -> tuple[dict[str, bytes], int]:
    """The trace's bytes, and how many whole passes the controller's own model made."""
    episode = Episode(scenario, plan=plan, effects=effects_for(plant))
    passes = [0]
    whole_pass = episode.controller_arm.compute

    def counted(q, v):
        passes[0] += 1
        return whole_pass(q, v)

    episode.controller_arm.compute = counted  # type: ignore[method-assign]
    episode.reset()
    for residual in residuals[: episode.n_steps]:
        episode.step(residual)
    return _trace_bytes(episode.trace()), passes[0]


@pytest.mark.parametrize(("seed", "plant"), [(0, "sim"), (3, "sim"), (1, "proxy")])
def test_a_mounted_pusher_pushes_as_with_the_controller_s_second_pass(
    seed: int, plant: str, monkeypatch
) -> None:
    scenario, _, plan = draw_planned_scenario(
        seed, "training", "cube", "chirp", plant=plant, duration=1.5
    )
    assert scenario.unknowns.has_mounting_error and scenario.unknowns.mount_yaw != 0.0
    # a residual that moves the reference offset, as a policy's would
    residuals = np.random.default_rng(seed).uniform(-0.005, 0.005, (plan.trajectory.n_steps, 3))
    fast, fast_passes = _push(scenario, plan, plant, residuals)
    monkeypatch.setattr(Episode, "controller_terms", _second_pass)
    slow, slow_passes = _push(scenario, plan, plant, residuals)
    assert fast_passes == 0 and slow_passes > 400  # one a step: approach and push
    assert fast.keys() == slow.keys()
    for name in fast:
        assert fast[name] == slow[name], name


def test_both_ways_to_the_controller_s_gravity_are_covered() -> None:
    """Seeds 0 and 3 above: the world's g (same plate centre to the bit) and the fallback."""
    seen = set()
    for seed in (0, 3):
        scenario, _, plan = draw_planned_scenario(
            seed, "training", "cube", "chirp", plant="sim", duration=1.5
        )
        believed = Episode(scenario, plan=plan)._believed
        assert believed is not None
        seen.add(believed.same_gravity)
    assert seen == {True, False}
