"""Compiling the simulator's kernels before a first command needs them.

numba compiles pushctl's kernels (the world step, the contact solve, the PD law, the
actuator and friction models, the batched actor) at their first call, about a minute of one
core, and keeps them in its disk cache. ``make install`` runs :func:`warm`, so the first
command starts at once; without it, the commands that push (:data:`COMPILING`) say they are
compiling when :func:`cache_is_cold`, rather than sit silent.

:func:`warm` goes through the commands' own paths (a short push of each object on each
plant kind with each controller, and one training episode), so it compiles whatever kernels
those paths call, wherever they are defined.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from pathlib import Path

from rich.console import Console

PACKAGE = Path(__file__).resolve().parent.parent
COMPILING = "compiling the simulator's kernels (first run only, a few minutes)…"
_KERNEL = re.compile(r"^@(?:numba\.)?njit", re.MULTILINE)
WARM_DURATION = 1.0
"""Seconds pushed by each of :func:`warm`'s pushes [s]: the gate opens and a prong slips."""


def cache_is_cold(package: Path = PACKAGE) -> bool:
    """True if some file of ``package`` that defines kernels has none in numba's cache
    (no index file beside it; with ``NUMBA_CACHE_DIR`` set, none anywhere there)."""
    elsewhere = os.environ.get("NUMBA_CACHE_DIR")
    if elsewhere:
        return not any(Path(elsewhere).rglob("*.nbi"))
    for path in package.rglob("*.py"):
        if _KERNEL.search(path.read_text(encoding="utf-8")):
            if not any((path.parent / "__pycache__").glob(f"{path.stem}.*.nbi")):
                return True
    return False


def note_if_cold(console: Console) -> None:
    """Say :data:`COMPILING` on ``console`` when the kernels' cache is cold."""
    if cache_is_cold():
        console.print(COMPILING, highlight=False, markup=False, soft_wrap=True)


STEPS = 7
""":func:`warm`'s steps: loading, four pushes (two objects, two plants), two training
episodes."""


def warm(report: Callable[[str], None] | None = None) -> None:
    """Compile every kernel a command calls: a :data:`WARM_DURATION` push of each object on
    the ``sim`` and ``proxy`` plants with each controller (the shipped policy for ``rl``),
    and one short training episode. A second call finds them cached: a few seconds.
    ``report`` is told each step as it starts (``step 2 of 6: …``) and the total at the end."""
    import time

    started = time.perf_counter()
    step = 0

    def say(what: str) -> None:
        nonlocal step
        step += 1
        if report is not None:
            took = time.perf_counter() - started
            report(f"step {step} of {STEPS}: {what} ({took // 60:.0f} min {took % 60:02.0f} s)")

    say("loading the simulator")
    from pushctl.cli.simulate_steps import push, simulate_scenario
    from pushctl.control import load_gains
    from pushctl.rl.env_config import EnvConfig
    from pushctl.rl.warm_up import compile_kernels

    gains = load_gains()
    unchanged = {"mu_ground": None, "mu_contact": None, "object_mass": None}
    for object_name in ("cube", "wedge"):
        for plant in ("sim", "proxy"):
            say(f"pushing the {object_name} on {plant} with each controller")
            scenario, _ = simulate_scenario(
                object_name, "chirp", None, 0, False, unchanged, WARM_DURATION,
                "kinova-gen2-7dof", plant,
            )  # fmt: skip
            for controller in ("pd", "feedback", "rl"):
                push(scenario, controller, gains, None, plant)
    for base_law in ("none", "feedback"):
        say(f"a training episode on base law {base_law}")
        compile_kernels(EnvConfig(base_law=base_law, action_repeat=10), gains, (16, 16))
    if report is not None:
        took = time.perf_counter() - started
        report(f"kernels compiled in {took // 60:.0f} min {took % 60:02.0f} s; cached for later")


def main() -> None:
    """``make install``'s last step: :func:`warm`, saying each step."""
    print("compiling the simulator's kernels, once (5-11 min on two cores):", flush=True)
    warm(report=lambda line: print(f"  {line}", flush=True))
