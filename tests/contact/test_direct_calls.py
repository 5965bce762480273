"""The world step's kernels called past numba's dispatcher (pushctl.contact.direct_calls)."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import pushctl
from benchmarks.suite import _pushing_world
from pushctl.contact import direct_calls
from pushctl.contact.step_end import prong_geometry


def test_the_suite_checks_every_direct_call() -> None:
    assert direct_calls.CHECK_CALLS, "tests/conftest.py sets PUSHCTL_CHECK_CALLS=1"


def test_a_checked_entry_point_refuses_an_argument_of_another_layout() -> None:
    edges, pose, prongs = np.zeros((4, 4)), np.zeros(3), np.zeros((2, 3))
    call = direct_calls.entry_point(prong_geometry, (edges, pose, prongs, 0.01))
    geometry, gaps, mask = call(edges, pose, prongs, 0.01)
    assert geometry.shape == (2, 5) and gaps.shape == (2,)
    strided = np.zeros(6)[::2]  # 1-d, not contiguous: numba types it "A", not "C"
    with pytest.raises(TypeError, match=r"prong_geometry called directly with arguments \[1\]"):
        call(edges, strided, prongs, 0.01)
    with pytest.raises(TypeError, match="with 3 arguments, not 4"):
        call(edges, pose, prongs)
    read_only = pose.copy()
    read_only.flags.writeable = False  # read as a writeable array is: accepted
    call(edges, read_only, prongs, 0.01)


def test_a_kernel_that_is_not_compiled_is_called_as_it_is() -> None:
    def wrapper(*args):
        return args

    assert direct_calls.entry_point(wrapper, (1, 2)) is wrapper


def _steps(world, torque, kv, n: int, strided: bool = False) -> bytes:
    out = []
    for _ in range(n):
        tau = torque()
        if strided:  # the same numbers in every other element of a longer array
            spaced = np.zeros(2 * tau.size)
            spaced[::2] = tau
            tau = spaced[::2]
        result = world.step(tau, implicit_kv=kv)
        out += [
            result.object_pose.tobytes(),
            result.arm_q.tobytes(),
            result.contact_forces.tobytes(),
        ]
    return b"".join(out)


def test_a_strided_torque_steps_as_its_contiguous_copy() -> None:
    """The step's kernels are resolved for a contiguous torque: a strided one is copied
    (``World._check_command``), else the compiled code would read it with the wrong stride."""
    assert _steps(*_pushing_world("cube"), 60) == _steps(*_pushing_world("cube"), 60, strided=True)


def test_a_copied_or_pickled_world_resolves_its_kernels_again() -> None:
    world, torque, kv = _pushing_world("wedge")
    assert world._slip_call is not None and world._end_call is not None  # stepped 100 times
    copied = copy.deepcopy(world)
    pickled = pickle.loads(pickle.dumps(world))
    assert copied._slip_call is None and pickled._slip_call is None
    taus = [torque() for _ in range(40)]
    runs = []
    for each in (world, copied, pickled):
        runs.append(b"".join(each.step(tau, implicit_kv=kv).object_pose.tobytes() for tau in taus))
    assert runs[0] == runs[1] == runs[2]


def test_an_object_only_world_steps_through_its_entry_point() -> None:
    world = pushctl.make_world(object="cube", arm=None)
    world.reset(object_velocity=(0.2, 0.05, 0.5))
    for _ in range(30):
        world.step()
    assert world._slip_call is not None
    assert np.all(np.abs(world.object_velocity) < 1e-9)  # friction stopped the sliding cube
