"""The :class:`Controller` protocol and the registry of controllers (docs/design.md §5).

A controller drives the push of one scenario's episode: it is given the episode as a reset
left it (a :class:`Start`) and returns the push's trace (a :class:`ControllerRun`; one per
policy for a controller that runs several). It is registered once, under its name, with what
the rest of the tool shows of it: a label and a colour for the figures, a one-line summary
for ``--help``, the loader of its own gains file::

    @register_controller("pd", label="PD-only", colour="#1f77b4", summary="PD-only")
    class PDOnly:
        def __init__(self, setup: PushSetup) -> None: ...
        def push(self, start: Start) -> tuple[ControllerRun, ...]: ...

The registry's order is the tables' column order and the order of the rows of one trial.
``pushctl simulate`` and ``pushctl evaluate`` run every controller through one function,
:func:`pushctl.controllers.drive.push_controllers`.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from pushctl.errors import ConfigError, StateError

if TYPE_CHECKING:  # the registry stays light: `pushctl --help` lists it without the simulator
    from pushctl.control.gains import PDGains
    from pushctl.episode.trace import Trace
    from pushctl.rl.networks import ActorPolicy
    from pushctl.task.env import PushEnv
    from pushctl.task.env_config import EnvConfig

__all__ = [
    "Controller",
    "ControllerEntry",
    "ControllerRun",
    "PushSetup",
    "Start",
    "check_controllers",
    "controller_entry",
    "controller_names",
    "entries",
    "paper_controllers",
    "register_controller",
    "unregister_controller",
]


@dataclass(frozen=True)
class PushSetup:
    """What every controller of one process is built from.

    ``config``: the push environment's settings (plant kind, stream, push length and step;
    a policy's own residual settings); ``gains``: the PD baseline's, under every controller;
    ``policies``: (actor, training seed) pairs, for a controller that pushes with a policy;
    ``controller_gains``: each controller's own gains by name (its entry's ``load_gains``).
    """

    config: EnvConfig
    gains: PDGains
    policies: tuple[tuple[ActorPolicy, int | None], ...] = ()
    controller_gains: Mapping[str, Any] = field(default_factory=dict)


class Start:
    """A scenario's episode as a reset left it, shared by the controllers of one trial.

    ``env``: a :class:`~pushctl.task.env.PushEnv` just reset to the scenario (not stepped);
    ``options``: the reset options that give it (a controller that cannot take the reset
    over resets its own environment with them); ``redrawn``: the goals redrawn to find it.
    A controller never steps ``env``: it pushes from a copy (:meth:`environment`).
    """

    def __init__(self, env: PushEnv, options: Mapping[str, Any], redrawn: int) -> None:
        if env.episode is None or env.episode.step_index != 0:
            raise StateError("a controller's start is an environment just reset, before a step")
        self.env = env
        self.options = dict(options)
        self.redrawn = redrawn
        self._final = False

    def environment(self, last: bool = True) -> PushEnv:
        """An environment to push in, as the reset left it: a deep copy of :attr:`env` (the
        same episode, approach and generators, to the byte), or :attr:`env` itself for the
        ``last`` push of the last controller (:func:`~pushctl.controllers.drive.push_controllers`
        runs them in turn), which saves the copy."""
        if self._final and last:
            self._final = False
            return self.env
        return copy.deepcopy(self.env)

    def hand_over(self) -> None:
        """Let the next ``last`` call of :meth:`environment` take :attr:`env` itself."""
        self._final = True


@dataclass(frozen=True)
class ControllerRun:
    """One push: its ``trace``, the share of its steps the gate was open (0 for a controller
    without a residual) and, for a policy, its training seed (None elsewhere)."""

    trace: Trace
    gate_share: float = 0.0
    policy_seed: int | None = None


class Controller(Protocol):
    """What drives a push: built from a :class:`PushSetup` (once per process and plant
    kind), it pushes a :class:`Start`'s scenario, leaving the start as it found it."""

    def push(self, start: Start) -> tuple[ControllerRun, ...]:
        """The push (or one per policy) of ``start``'s scenario."""
        ...


@dataclass(frozen=True)
class ControllerEntry:
    """A registered controller.

    ``name``: the CLI's and the CSVs' name; ``factory``: builds it from a
    :class:`PushSetup`; ``label``: the figures' legend; ``colour``: its lines (a matplotlib
    colour); ``width``: their width [pt] (narrower on top); ``summary``: a few words for
    ``--help``; ``load_gains``: reads its gains file (None: it has none beyond the PD's),
    called before any push so a bad file fails first; ``describe_gains``: those gains in
    the evaluation's provenance line; ``needs_policy``: it pushes with a policy file;
    ``any_pusher``: it pushes with any pusher (a policy knows the paper's only);
    ``has_gate``: its pushes go through the gate (its share is in the tables); ``paper``:
    one of the paper's comparison: ``--controller all`` runs it and the tables always have
    its columns (any other controller's when it ran)."""

    name: str
    factory: Callable[[PushSetup], Controller]
    label: str
    colour: str
    summary: str
    width: float = 1.5
    load_gains: Callable[[], Any] | None = None
    describe_gains: Callable[[Any], str] | None = None
    needs_policy: bool = False
    any_pusher: bool = True
    has_gate: bool = True
    paper: bool = False


_REGISTRY: dict[str, ControllerEntry] = {}


def register_controller(
    name: str, **entry: Any
) -> Callable[[Callable[[PushSetup], Controller]], Callable[[PushSetup], Controller]]:
    """A decorator registering its class (or factory function) as controller ``name`` with
    the :class:`ControllerEntry` fields ``entry``; ConfigError if the name is taken or is
    not a plain lower-case word (it names CSV columns: ``force_error_<name>_sim``)."""

    def register(factory: Callable[[PushSetup], Controller]) -> Callable[[PushSetup], Controller]:
        if name in _REGISTRY:
            raise ConfigError(f"controller {name!r} is registered already")
        if not name.isidentifier() or name != name.lower() or name == "all":
            raise ConfigError(f"controller name {name!r}: use a lower-case word, not 'all'")
        _REGISTRY[name] = ControllerEntry(name=name, factory=factory, **entry)
        return factory

    return register


def unregister_controller(name: str) -> None:
    """Remove controller ``name`` from the registry (tests register toys for a while)."""
    _REGISTRY.pop(name, None)


def controller_names() -> tuple[str, ...]:
    """Every registered controller, in the registry's order (the tables')."""
    return tuple(_REGISTRY)


def paper_controllers() -> tuple[str, ...]:
    """The paper's comparison (``--controller all``): PD-only, feedback, RL-assisted."""
    return tuple(name for name, entry in _REGISTRY.items() if entry.paper)


def controller_entry(name: str) -> ControllerEntry:
    """The entry of ``name``; ConfigError (one line, naming those accepted) if none."""
    if name not in _REGISTRY:
        raise ConfigError(f"unknown controller {name!r}; accepted: {', '.join(controller_names())}")
    return _REGISTRY[name]


def check_controllers(names: tuple[str, ...] | list[str]) -> None:
    """ConfigError for the first of ``names`` that is not registered."""
    for name in names:
        controller_entry(name)


def entries(names: tuple[str, ...] | list[str] | None = None) -> Iterator[ControllerEntry]:
    """The entries of ``names`` (default: all), in the registry's order."""
    chosen = controller_names() if names is None else names
    return (controller_entry(name) for name in controller_names() if name in chosen)
