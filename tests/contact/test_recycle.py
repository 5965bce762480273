"""A step's arrays are taken again only once nothing outside the world holds them."""

import numpy as np
import pytest

import pushctl
from benchmarks.suite import _pushing_world
from pushctl.contact.recycle import ArrayRecycler, set_recycling
from pushctl.task.env import PushEnv
from pushctl.task.env_config import EnvConfig


@pytest.fixture(autouse=True)
def recycling():
    """Recycling is opt-in: these tests turn it on, and leave it as they found it."""
    previous = set_recycling(True)
    yield
    set_recycling(previous)


def test_recycling_is_off_by_default_and_then_every_step_gets_new_arrays():
    set_recycling(False)
    recycler = ArrayRecycler(((3,),))
    first, second, third = recycler.take(), recycler.take(), recycler.take()
    assert len({id(first[0]), id(second[0]), id(third[0])}) == 3
    assert recycler._newer is None  # nothing kept to hand out again


def test_a_set_comes_back_the_step_after_next_when_nothing_holds_it():
    recycler = ArrayRecycler(((3,), (2, 2)))
    first = recycler.take()
    ids = [id(a) for a in first]
    del first
    recycler.take()
    again = recycler.take()
    assert [id(a) for a in again] == ids
    assert [a.shape for a in again] == [(3,), (2, 2)]


def test_a_set_with_one_array_held_elsewhere_is_never_taken_again():
    recycler = ArrayRecycler(((3,), (2, 2)))
    first = recycler.take()
    held = first[1]  # a caller keeps one array (a view would hold it too)
    view = first[0][:2]
    del first
    recycler.take()
    again = recycler.take()
    assert again[1] is not held and again[0] is not view.base
    held[:] = 7.0
    view[:] = 5.0
    for _ in range(4):
        arrays = recycler.take()
        arrays[0][:] = arrays[1][:] = -1.0  # what a step does to the arrays it takes
    assert (held == 7.0).all() and (view == 5.0).all()


def test_results_a_caller_keeps_are_never_written_by_later_steps():
    """Keep every third step's result and arm terms: their bytes stay what the step
    returned, while the steps in between still take their arrays again."""
    world, torque, kv = _pushing_world("cube")
    kept, taken = [], 0
    for n in range(60):
        before = world._end_arrays._older
        result = world.step(torque(), implicit_kv=kv)
        taken += world._end_arrays._newer is before
        if n % 3 == 0:
            terms = world.arm_terms
            arrays = [*vars(result).values(), *terms]
            copies = [a.copy() for a in arrays if isinstance(a, np.ndarray)]
            kept.append((arrays, copies))
    for arrays, copies in kept:
        held = [a for a in arrays if isinstance(a, np.ndarray)]
        assert all(a.tobytes() == c.tobytes() for a, c in zip(held, copies, strict=True))
    assert taken > 20  # the steps whose arrays nobody kept were taken again


def _pushing_trajectory() -> bytes:
    """300 steps of the bench's pushing world, as bytes (a kept array would not be taken
    again)."""
    world, torque, kv = _pushing_world("wedge")
    out = []
    for _ in range(300):
        result = world.step(torque(), implicit_kv=kv)
        step = [result.object_pose, result.contact_forces, result.arm_q, result.arm_v]
        out += [np.ascontiguousarray(a).tobytes() for a in (*step, *world.arm_terms)]
    return b"".join(out)


def _mounted_push() -> bytes:
    """A reset and 1.5 s of a ``sim`` push with random actions: a pusher with a mounting
    error, so the step end's set holds the nominal frame's arrays too."""
    env = PushEnv(EnvConfig(duration=1.5, gate_threshold=0.0))
    observation, _ = env.reset(seed=2)
    assert env.episode is not None and env.episode.world.arm.nominal_frame >= 0
    rng, out = np.random.default_rng(0), [observation.tobytes()]
    while not env.episode.done:
        observation, reward, *_ = env.step(rng.uniform(-1, 1, 3).astype(np.float32))
        out += [observation.tobytes(), np.float64(reward).tobytes()]
    return b"".join(out)


@pytest.mark.parametrize("trajectory", [_pushing_trajectory, _mounted_push])
def test_the_same_trajectory_with_and_without_taking_arrays_again(monkeypatch, trajectory):
    """A step writes every element of a set it takes again before anything reads it: with
    each set poisoned with NaN as it is taken again, the same bytes as with new arrays
    every step (the recycler made to find nothing free)."""
    all_free, poisoned = pushctl.contact.recycle._all_free, []

    def poisoning(arrays, free):
        if not all_free(arrays, free):
            return False
        for array in arrays:
            array.fill(np.nan)
        poisoned.append(1)
        return True

    monkeypatch.setattr(pushctl.contact.recycle, "_all_free", poisoning)
    recycling = trajectory()
    assert len(poisoned) > 250  # sets were taken again on most steps
    monkeypatch.setattr(pushctl.contact.recycle, "_all_free", lambda arrays, free: False)
    assert trajectory() == recycling
