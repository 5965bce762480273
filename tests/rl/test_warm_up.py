"""The kernel warm-up before a multi-seed run pushes through the slipping (cold MLCP) path
and the PD-only push, and touches no global random state a run could depend on."""

from __future__ import annotations

import numpy as np
import torch

from pushctl.control.gains import load_gains
from pushctl.rl.presets import load_preset
from pushctl.rl.warm_up import compile_kernels


def test_the_warm_up_slips_pushes_pd_only_and_leaves_global_generators_alone() -> None:
    preset = load_preset("paper")
    torch.manual_seed(5)
    # the legacy global generator, to show nothing draws from it
    numpy_state = np.random.get_state()[1].copy()  # noqa: NPY002
    torch_state = torch.get_rng_state().clone()
    record = compile_kernels(preset.env, load_gains(), preset.ddpg.hidden)
    assert record.rl["slip_fraction"] > 0.0  # the cold MLCP path and its pivoting ran
    assert record.gate_open_fraction > 0.0  # the actor acted
    assert record.pd is not None and record.pd["slip_fraction"] < record.rl["slip_fraction"]
    assert np.array_equal(np.random.get_state()[1], numpy_state)  # noqa: NPY002
    assert torch.equal(torch.get_rng_state(), torch_state)
