"""``pd``: PD-only, the paper's π_H (docs/design.md §5): the joint PD baseline follows the
plan (:mod:`pushctl.control.pd`), with no residual."""

from __future__ import annotations

from pushctl.controllers.base import ControllerRun, PushSetup, Start, register_controller


@register_controller(
    "pd",
    label="PD-only",
    colour="#1f77b4",
    width=2.6,
    summary="PD-only",
    has_gate=False,
    paper=True,
)
class PDOnly:
    """PD-only. It pushes from a copy of the episode as the approach left it, the prongs
    where the approach landed them (:func:`~pushctl.rl.policy.pd_only_episode`: it is open
    loop in the object's pose, so it is not re-landed); the trace of a fresh
    ``Episode(scenario, gains, …).run()``, without running the approach again."""

    def __init__(self, setup: PushSetup) -> None:
        del setup  # the PD gains are the start's environment's

    def push(self, start: Start) -> tuple[ControllerRun, ...]:
        from pushctl.rl.policy import pd_only_episode

        return (ControllerRun(pd_only_episode(start.env).finish()),)
