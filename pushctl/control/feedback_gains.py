"""The ``feedback`` law's settings (:class:`FeedbackGains`) and their TOML file.

``pushctl/defaults/feedback_gains.toml`` holds the law: the steady PI law's gains (``pushctl
tune-feedback`` tunes them) and a catch-up phase (``catchup_*`` keys and the law's own gate,
searched by ``python -m studies.catchup_search``); ``pushctl/defaults/feedback_gains_v1.toml`` keeps
the steady law alone, the one the earlier results used. For the first ``catchup_time`` seconds of a
push the law runs at ``catchup_k``/``catchup_k_i`` with its caps relaxed to
``catchup_lateral_ratio``/``catchup_turn_ratio``, but only on steps where every prong carries
at least ``catchup_force``: relaxed caps while a prong is barely loaded started a single-prong
spin on a wedge trapezoid tuning push (63 % angle error), which is what the caps are for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from pushctl.defaults import default_file
from pushctl.errors import ConfigError
from pushctl.files.toml import check_keys, read_toml
from pushctl.ranges import check_range

DEFAULT_FEEDBACK_FILE = default_file("feedback_gains.toml")
"""The law every command uses: the steady gains and the catch-up phase."""

STEADY_FEEDBACK_FILE = default_file("feedback_gains_v1.toml")
"""The steady law without a catch-up phase (the earlier default), kept under its own name."""

_NON_NEGATIVE = (
    "k",
    "k_i",
    "contact_force",
    "seek_rate",
    "seek_ramp",
    "smoothing",
    "slide_filter",
    "catchup_time",
    "catchup_k",
    "catchup_k_i",
    "catchup_force",
    "catchup_gate",
)
_CAPS = (
    "lateral_ratio",
    "turn_ratio",
    "slide_limit",
    "catchup_lateral_ratio",
    "catchup_turn_ratio",
)


@dataclass(frozen=True)
class FeedbackGains:
    """``k`` [1/s] and ``k_i`` [1/s²]: the proportional and integral gains, one each for the
    translation and the angle error; ``contact_force`` [N]: the integral is frozen while a
    prong's measured normal force is below it; ``hold_off_contact``: then the whole output
    is zero too. On the ``reference`` path the P term is itself integrated into the offset,
    and a correction that made a prong lose contact would otherwise wind the offset up
    (tens of mm and degrees on the tuning pushes, docs/residual-and-feedback.md).
    ``lateral_ratio`` [-]: the sideways rate's cap as a fraction of the plan's speed
    (``inf``: no cap). ``seek_rate`` [rad/s]: the turn that re-closes a prong's gap while
    others carry load (0: hold still then too), reached ``seek_ramp`` [s] after a prong
    came off (0: at once). ``turn_ratio`` [-]: the object turn's cap, as the speed it gives
    the farthest prong about the object's centre over the plan's speed (``inf``: no cap).
    ``smoothing`` [s]: the time constant of a first-order lag on the output (0: none).
    ``slide_limit`` [m]: how far the prongs may have moved across the push from where they
    landed before the law stops pushing sideways that way (``inf``, the default: never
    stops), as read through a first-order lag of ``slide_filter`` [s] (0: none; the
    proxy's camera has σ = 1 mm).

    The catch-up phase, the push's first ``catchup_time`` [s] (0, the default: none): gains
    ``catchup_k`` [1/s] and ``catchup_k_i`` [1/s²]; caps ``catchup_lateral_ratio`` and
    ``catchup_turn_ratio`` [-] on the steps where every prong's measured normal force is at
    least ``catchup_force`` [N] (the steady caps on the others).

    The gate: ``gate_threshold`` [m] (None, the default: the environment's gate decides when
    the law acts, as before the catch-up existed). A number: the law has its own dead band,
    the pose deviation √(e_x² + e_y² + (gate_length·e_θ)²) at or below which it outputs zero
    and leaves its state alone, ``catchup_gate`` [m] during the catch-up and
    ``gate_threshold`` after; the environment's gate must then be open
    (:func:`~pushctl.controllers.feedback.feedback_config` opens it)."""

    k: float = 0.5
    k_i: float = 0.0
    contact_force: float = 0.05
    hold_off_contact: bool = True
    lateral_ratio: float = 0.05
    seek_rate: float = 0.1
    seek_ramp: float = 0.2
    turn_ratio: float = 0.05
    smoothing: float = 0.1
    slide_limit: float = math.inf
    slide_filter: float = 1.0
    catchup_time: float = 0.0
    catchup_k: float = 3.0
    catchup_k_i: float = 0.1
    catchup_lateral_ratio: float = 0.15
    catchup_turn_ratio: float = 0.15
    catchup_force: float = 0.05
    catchup_gate: float = 0.0
    gate_threshold: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.hold_off_contact, bool):
            raise ConfigError(
                f"feedback hold_off_contact must be true or false, got {self.hold_off_contact!r}"
            )
        for name in _NON_NEGATIVE:
            value = getattr(self, name)
            ok = isinstance(value, int | float) and not isinstance(value, bool)
            if not ok or not math.isfinite(value) or value < 0.0:
                raise ConfigError(f"feedback {name} must be a finite number >= 0, got {value!r}")
        for name in ("k", "k_i", "contact_force"):
            check_range(f"feedback {name}", getattr(self, name))
        for name in _CAPS:
            ratio = getattr(self, name)
            if isinstance(ratio, bool) or not isinstance(ratio, int | float) or not ratio >= 0.0:
                raise ConfigError(
                    f"feedback {name} must be a number >= 0 (inf: no cap), got {ratio!r}"
                )
        gate = self.gate_threshold
        if gate is not None and (
            isinstance(gate, bool)
            or not isinstance(gate, int | float)
            or not math.isfinite(gate)
            or gate < 0.0
        ):
            raise ConfigError(
                f"feedback gate_threshold must be a finite number >= 0 [m], got {gate!r}"
            )

    @property
    def owns_gate(self) -> bool:
        """Whether the law gates itself (then the environment's gate must be open)."""
        return self.gate_threshold is not None


def load_feedback_gains(path: str | Path | None = None) -> FeedbackGains:
    """The ``[feedback]`` table of ``path`` (default :data:`DEFAULT_FEEDBACK_FILE`);
    ConfigError (one line) for a missing file, a missing table or a bad key."""
    path = Path(path) if path is not None else DEFAULT_FEEDBACK_FILE
    data: dict[str, Any] = read_toml(path, "feedback gains file")
    table = data.get("feedback")
    if not isinstance(table, dict):
        raise ConfigError(f"{path}: no [feedback] table; expected k, k_i and contact_force")
    names = [item.name for item in fields(FeedbackGains)]
    check_keys(table, names, f"{path} [feedback]", all_required=False)
    try:
        return FeedbackGains(**table)
    except ConfigError as exc:
        raise ConfigError(f"feedback gains file {path}: {exc}") from None


def feedback_table(gains: FeedbackGains) -> list[str]:
    """The ``[feedback]`` table's lines for ``gains`` (``gate_threshold`` only if set)."""
    lines = ["[feedback]"]
    for item in fields(FeedbackGains):
        value = getattr(gains, item.name)
        if value is None:
            continue
        if isinstance(value, bool):
            text = "true" if value else "false"
        else:
            value = float(value)
            text = repr(value) if math.isfinite(value) else "inf"
        lines.append(f"{item.name} = {text}")
    return lines
