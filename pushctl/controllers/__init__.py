"""Controllers: what drives a push, each a type registered under its name
(:mod:`pushctl.controllers.base`: the :class:`Controller` protocol and the registry;
:mod:`pushctl.controllers.drive`: the one driver ``simulate`` and ``evaluate`` share).

The registry's entries: the modules below, imported in the tables' order. A new controller
is a module here and one line below (docs/howto/add-a-controller.md).
"""

# isort: off
# the registry's entries: importing a module registers its controller, in this order
from pushctl.controllers import pd  # noqa: F401
from pushctl.controllers import feedback  # noqa: F401
from pushctl.controllers import policy  # noqa: F401

# isort: on
from pushctl.controllers.base import (
    Controller,
    ControllerEntry,
    ControllerRun,
    PushSetup,
    Start,
    check_controllers,
    controller_entry,
    controller_names,
    entries,
    paper_controllers,
    register_controller,
    unregister_controller,
)

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
