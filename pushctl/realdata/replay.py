"""Replaying recorded single pushes in the kinematic world, spread over worker processes.

Each push is independent (a fresh world, no warm start carried over), so the predictions
do not depend on the number of workers or on the order of the rows.
"""

from __future__ import annotations

import math
import multiprocessing
import signal
from collections.abc import Mapping
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np
import pandas as pd

from pushctl.errors import ConfigError
from pushctl.kinematic import Friction, KinematicPushWorld, PressurePrior, Pusher, Slider
from pushctl.realdata.data import TIP_RADIUS, plate_mass

DEFAULT_FACETS = 16
"""The polygon friction's sides in the replays by default: on the calibration split the
16-gon fits both surfaces better than the 8-gon (docs/realdata.md §5) at about the same
replay time."""


@dataclass(frozen=True)
class SurfaceParameters:
    """What is fitted per surface: prong–object μ_c, object–table μ_g [-] and the pressure
    prior's ``rim_weight`` (:class:`~pushctl.kinematic.PressurePrior`)."""

    mu_contact: float = 0.25
    mu_ground: float = 0.3
    rim_weight: float = 0.0


@dataclass(frozen=True)
class ReplaySettings:
    """How pushes are simulated: ``step_length`` [m] the tip moves per step (dt follows
    from each push's speed), the ground ``friction_model`` (the world's,
    :data:`pushctl.contact.world.FRICTION_MODELS`, with ``facets`` sides for the polygon)
    and ``support_count``."""

    step_length: float = 2e-3
    friction_model: str = "polygon"
    support_count: int = 16
    facets: int = DEFAULT_FACETS

    def __post_init__(self) -> None:
        if not (math.isfinite(self.step_length) and 1e-4 <= self.step_length <= 0.01):
            raise ConfigError(f"step length must be 0.1-10 mm, got {self.step_length!r} m")
        Friction(model=self.friction_model, facets=self.facets)  # the world's checks


def replay_pushes(
    pushes: pd.DataFrame,
    shapes: Mapping[str, np.ndarray],
    params: Mapping[str, SurfaceParameters],
    settings: ReplaySettings = ReplaySettings(),
    workers: int = 1,
) -> np.ndarray:
    """Predicted end poses (N, 3) [m, m, rad] of the pose frame, one per row of ``pushes``.

    ``params`` maps each surface in ``pushes`` to its parameters."""
    missing = sorted(set(pushes["surface"]) - set(params))
    if missing:
        raise ConfigError(
            f"the friction fit has no parameters for surface(s) {', '.join(missing)} of the data"
        )
    columns = ["x0", "y0", "theta0", "tip_x0", "tip_y0", "tip_x1", "tip_y1", "speed_mm_s"]
    jobs = []
    for (surface, shape), index in sorted(pushes.groupby(["surface", "shape"]).groups.items()):
        rows = pushes.loc[index, columns].to_numpy(dtype=float)
        jobs.append((pushes.index.get_indexer(index), shapes[shape], params[surface], rows))
    chunks = [(idx[i : i + 64], v, p, r[i : i + 64]) for idx, v, p, r in jobs
              for i in range(0, len(idx), 64)]  # fmt: skip
    out = np.empty((len(pushes), 3))
    if workers <= 1 or len(chunks) <= 1:
        for idx, vertices, p, rows in chunks:
            out[idx] = _replay_chunk(vertices, p, rows, settings)
        return out
    _replay_chunk(chunks[0][1], chunks[0][2], chunks[0][3][:1], settings)  # compile before fork
    context = multiprocessing.get_context("fork")
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_stop_on_signals)
    try:
        futures = [pool.submit(_replay_chunk, v, p, r, settings) for _, v, p, r in chunks]
        for (idx, *_), future in zip(chunks, futures, strict=True):
            out[idx] = future.result()
    except BaseException:  # stopped (Ctrl-C, SIGTERM) or failed: the workers go at once
        pool.shutdown(wait=False, cancel_futures=True)
        for process in list((pool._processes or {}).values()):
            process.terminate()
        raise
    pool.shutdown()
    return out


def _stop_on_signals() -> None:
    """A worker ends at SIGTERM and leaves Ctrl-C to the command, which stops the pool: a
    forked worker would otherwise inherit the command's handlers and go on with its queue."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _replay_chunk(
    vertices: np.ndarray, params: SurfaceParameters, rows: np.ndarray, settings: ReplaySettings
) -> np.ndarray:
    """End poses (n, 3) of n pushes of one shape on one surface; ``rows`` (n, 8) holds
    x0, y0, θ0, tip start and end, speed [mm/s]."""
    slider = Slider.from_vertices(
        vertices, plate_mass(vertices), PressurePrior(settings.support_count, params.rim_weight)
    )
    friction = Friction(
        params.mu_contact, params.mu_ground, settings.friction_model, settings.facets
    )
    out = np.empty((len(rows), 3))
    worlds: dict[float, KinematicPushWorld] = {}  # one per step length [s], reset per push
    pusher = Pusher(((0.0, 0.0),), TIP_RADIUS)
    for i, (x0, y0, th0, tx0, ty0, tx1, ty1, speed) in enumerate(rows.tolist()):
        dt = settings.step_length / (speed * 1e-3)
        length = math.hypot(tx1 - tx0, ty1 - ty0)
        heading = math.atan2(ty1 - ty0, tx1 - tx0)
        steps = max(1, math.ceil(length / settings.step_length - 1e-9))
        s = np.minimum(np.arange(steps + 1) * settings.step_length / max(length, 1e-12), 1.0)
        path = np.column_stack(
            (tx0 + s * (tx1 - tx0), ty0 + s * (ty1 - ty0), np.full_like(s, heading))
        )
        world = worlds.get(dt)
        if world is None:
            world = worlds[dt] = KinematicPushWorld(slider, pusher, friction, dt)
        world.reset((x0, y0, th0))
        for k in range(steps):
            world.step(path[k], path[k + 1])
        out[i] = world.pose
    return out
