"""The reality proxy's state through one run of an episode: its actuators, the camera's
noise for every frame of the push, and the force estimate's generator, all fresh at every
reset (:class:`~pushctl.episode.runner.Episode`). The proxy's effects themselves:
:mod:`pushctl.episode.proxy`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pushctl.episode.proxy import (
    ProxyActuators,
    ProxyEffects,
    camera_frames,
    camera_poses,
    draw_camera_noise,
    proxy_rng,
)


class ProxyRun:
    """The proxy's state for a run from the world's reset state: ``actuators`` (holding the
    arm until the first command arrives), ``camera`` (frames, 3) the camera's noise of every
    frame of the push [m, m, rad], and the force estimate's generator. ``t`` (N + 1,) [s]:
    the push's sample times; ``seed`` and ``case`` (object/profile) name the draws."""

    def __init__(
        self,
        effects: ProxyEffects,
        world: Any,
        t: np.ndarray,
        seed: int | None,
        case: str,
    ) -> None:
        self.effects = effects
        self.actuators = ProxyActuators(effects, world.v.size, world.gravity_torque())
        frames = camera_frames(float(t[-1]), effects.camera_rate)
        self.camera = draw_camera_noise(effects, frames, proxy_rng(seed, "camera", case))
        # each frame's last sample at or before its time k / rate (measured_pose reads it)
        taken = np.arange(frames) / effects.camera_rate
        self.frame_samples: list[int] = (np.searchsorted(t, taken, side="right") - 1).tolist()
        self.force_rng = proxy_rng(seed, "force", case)

    def measured_pose(self, poses: np.ndarray, t: np.ndarray, n: int) -> np.ndarray:
        """The camera's latest frame at step ``n``: the pose at the frame's time, from the
        recorded ``poses`` (rows, 3) at times ``t`` [s], plus its noise (as
        :func:`~pushctl.episode.proxy.camera_poses` gives the trace's ``measured_pose``)."""
        rate = self.effects.camera_rate
        frame = math.floor(float(t[n]) * rate + 1e-9)
        taken = frame / rate
        # the last sample at or before the frame's time, and the next one (interpolated)
        k = min(self.frame_samples[frame], n)
        pose = poses[k]
        if k < n and taken != t[k]:  # np.interp's arithmetic
            slope = (poses[k + 1] - pose) / (t[k + 1] - t[k])
            pose = slope * (taken - t[k]) + pose
        return pose + self.camera[frame]

    def measured_forces(self, forces: np.ndarray) -> np.ndarray:
        """Contact forces ``forces`` [N] with the force estimate's noise (one draw)."""
        return self.effects.noisy_forces(forces, self.force_rng)

    def camera_poses(self, t: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """The camera's poses of the recorded ``poses`` at times ``t`` (the trace's)."""
        return camera_poses(t, poses, self.effects.camera_rate, self.camera)
