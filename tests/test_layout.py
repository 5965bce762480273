"""The package's layout shows its architecture: no import cycle between pushctl's modules,
imports flowing one way through the layers (no exceptions), a top level holding only the
shared basics, modules short enough to read, one command line, and nothing in the installed
package that belongs to the checkout (the benchmarks and studies).

The import graph is read from the source with :mod:`ast` (every ``import`` statement,
including those inside functions and under ``TYPE_CHECKING``: a deferred import is still a
dependency), so the test needs no import of the package.
"""

from __future__ import annotations

import ast
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "pushctl"
MAX_LINES = 600
"""No module longer than this. Past about 400 lines a module is a prompt to check that it
still does one job; a module of one job may be longer, and a class is never sliced to fit."""

TOP_LEVEL = {
    "__init__.py",
    "types.py",  # shared value types
    "errors.py",  # typed errors
    "config.py",  # frozen settings shared by the layers
    "checks.py",  # argument checks
    "ranges.py",  # the sane range of every physical value a user gives
    "version.py",  # the version every provenance line names
    "engines.py",  # make_world: our contact world or MuJoCo's, above both engines
}
"""At most eight modules at the top; the rest is grouped by concept in subpackages (files,
the machine, the defaults, ...)."""

# The layer of each subpackage or top-level module: one per package, never one for a module
# inside a package (test_every_layer_is_a_whole_package). A module may import only
# modules of its own layer or lower. cli → report → runs → evaluation → controllers → rl →
# task → episode → control / planning → contact / mujoco → arm / objects, with the shared
# basics below all; ``pushctl`` itself (the public API, which re-exports from below) above
# all. A new subpackage or top-level module gets its entry here.
LAYERS = {
    "pushctl": 12,  # only the package's own __init__: its API re-exports from every layer
    "pushctl.cli": 11,
    "pushctl.report": 10,  # tables and figures from the evaluation's results
    "pushctl.reproduce": 10,  # make reproduce-tables: the other commands in turn, a manifest
    "pushctl.runs": 9,  # several training runs: seeds, sweeps
    "pushctl.evaluation": 8,
    "pushctl.realdata": 8,  # recorded pushes replayed and scored
    "pushctl.controllers": 7,  # the Controller protocol and registry: PD, the law, a policy
    "pushctl.rl": 6,  # learners
    "pushctl.task": 5,  # the push task: the environment a controller or learner pushes in
    "pushctl.episode": 4,
    "pushctl.control": 3,
    "pushctl.planning": 3,
    "pushctl.engines": 3,  # make_world: picks one of the two engines below
    "pushctl.contact": 2,
    "pushctl.mujoco": 2,  # the other engine: a peer of contact (pushctl.engines picks)
    "pushctl.kinematic": 2,  # a pusher on a prescribed path: the contact step, no arm
    "pushctl.arm": 1,
    "pushctl.objects": 1,
    "pushctl.distributed": 0,  # the Ray session and worker pool: infrastructure
    "pushctl.native": 0,  # the compiled library (Pinocchio's, ProxSuite's calls): no pushctl
    "pushctl.types": 0,
    "pushctl.errors": 0,
    "pushctl.config": 0,
    "pushctl.checks": 0,
    "pushctl.ranges": 0,
    "pushctl.machine": 0,  # the machine: CPU code, kernel cache, ProxQP's build
    "pushctl.files": 0,  # atomic writes, provenance, output locks, TOML
    "pushctl.version": 0,
    "pushctl.defaults": 0,  # the shipped gains, ranges and presets (package data)
}
CHECKOUT_ONLY = ("benchmarks", "studies")
"""Top-level directories of the checkout that are not installed: the package never imports
them."""
COMMAND_LINE_MAIN = PACKAGE / "cli" / "__main__.py"
"""The package's one ``__main__``: ``python -m pushctl.cli``, the ``pushctl`` command."""


def _modules() -> dict[str, tuple[Path, bool]]:
    """Dotted name → (file, is a package's ``__init__``)."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts.pop()
        found[".".join(parts)] = (path, is_package)
    return found


def import_graph() -> dict[str, set[str]]:
    """Module → the pushctl modules it imports (``from pkg import name`` counts as importing
    ``pkg.name`` when that is a module, else ``pkg``)."""
    modules = _modules()

    def known(name: str) -> str:
        while name not in modules:
            name = name.rpartition(".")[0]
        return name

    graph: dict[str, set[str]] = {}
    for name, (path, is_package) in modules.items():
        targets: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                targets |= {known(a.name) for a in node.names if a.name.startswith("pushctl")}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = name if is_package else name.rpartition(".")[0]
                    for _ in range(node.level - 1):
                        anchor = anchor.rpartition(".")[0]
                    base = f"{anchor}.{base}" if base else anchor
                if base.split(".")[0] != "pushctl":
                    continue
                for alias in node.names:
                    child = f"{base}.{alias.name}"
                    targets.add(child if child in modules else known(base))
        graph[name] = targets - {name}
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle as a list of modules (first repeated at the end), or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for target in sorted(graph[node]):
            if state.get(target) == 1:
                return path[path.index(target) :] + [target]
            if target not in state and (cycle := visit(target)):
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def layer(module: str) -> int | None:
    """The layer of ``module``: its own entry, else its closest package's below the root
    (the root's entry is the package's ``__init__`` alone)."""
    if module == "pushctl":
        return LAYERS["pushctl"]
    name = module
    while name != "pushctl":
        if name in LAYERS:
            return LAYERS[name]
        name = name.rpartition(".")[0]
    return None


def test_the_import_graph_is_read() -> None:
    graph = import_graph()
    # known edges, so a parser that read nothing would fail here rather than pass below
    assert "pushctl.contact.world" in graph["pushctl.episode.runner"]
    assert "pushctl.cli.common" in graph["pushctl.cli.plan"]
    assert "pushctl.objects.geometry" in graph["pushctl.objects.spec"]
    assert len(graph) > 100


def test_no_import_cycle() -> None:
    assert find_cycle(import_graph()) is None


def test_find_cycle_finds_one() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert find_cycle(graph) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_imports_flow_one_way_through_the_layers() -> None:
    upward = []
    for module, targets in import_graph().items():
        for target in targets:
            assert layer(module) is not None, f"{module} has no layer in LAYERS"
            assert layer(target) is not None, f"{target} has no layer in LAYERS"
            if layer(target) > layer(module):
                upward.append(f"{module} (layer {layer(module)}) imports {target} "
                              f"(layer {layer(target)})")  # fmt: skip
    assert upward == []


def test_every_layer_is_a_whole_package() -> None:
    """No exceptions: an entry names a subpackage or a top-level module, so that a package's
    modules share its layer."""
    modules = _modules()
    for name in LAYERS:
        if name == "pushctl":
            continue
        assert name.count(".") == 1, f"{name}: a layer for a module inside a package"
        assert name in modules, f"{name}: no such subpackage or module"


def _package(module: str) -> str:
    """The subpackage or top-level module ``module`` belongs to (``pushctl`` for the root)."""
    return ".".join(module.split(".")[:2])


def test_no_import_cycle_between_packages() -> None:
    """A package importing another that imports it back is a loop even when no module
    does: the packages' graph has no cycle (the root, which re-exports, left out)."""
    packages: dict[str, set[str]] = {}
    for module, targets in import_graph().items():
        if module == "pushctl":
            continue
        edges = packages.setdefault(_package(module), set())
        edges |= {_package(t) for t in targets if t != "pushctl"} - {_package(module)}
    for edges in packages.values():
        edges &= set(packages)
    assert find_cycle(packages) is None


def test_the_layers_are_read() -> None:
    assert layer("pushctl") == 12 and layer("pushctl.cli.plan") == 11
    assert layer("pushctl.runs.seeds") == 9 and layer("pushctl.distributed.engine") == 0
    assert layer("pushctl.controllers.pd") == 7
    assert layer("pushctl.nowhere") is None  # a new top-level module needs its entry


def test_the_core_never_imports_the_command_line() -> None:
    for module, targets in import_graph().items():
        if module.startswith("pushctl.cli") or module == "pushctl":
            continue
        assert not {t for t in targets if t.startswith("pushctl.cli")}, module


def _imported_top_level_names(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_the_package_never_imports_the_checkout_s_benchmarks_or_studies() -> None:
    importers = {
        path.relative_to(ROOT).as_posix()
        for path in PACKAGE.rglob("*.py")
        if _imported_top_level_names(path) & set(CHECKOUT_ONLY)
    }
    assert importers == set()


def test_the_installed_package_holds_no_benchmarks_or_studies() -> None:
    """Only ``pushctl*`` is packaged; the benchmarks and studies live beside it, each a
    package of its own run from the checkout (``python -m benchmarks.suite``)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert project["tool"]["setuptools"]["packages"]["find"]["include"] == ["pushctl*"]
    assert not (PACKAGE / "bench").exists()
    for directory in CHECKOUT_ONLY:
        assert (ROOT / directory / "__init__.py").is_file(), directory


def test_top_level_holds_only_the_shared_basics() -> None:
    files = {p.name for p in PACKAGE.iterdir() if p.suffix == ".py"}
    assert files == TOP_LEVEL


def test_no_module_is_longer_than_the_limit() -> None:
    lengths = {
        path.relative_to(ROOT).as_posix(): len(path.read_text().splitlines())
        for path in PACKAGE.rglob("*.py")
    }
    assert len(lengths) > 100
    assert {name: n for name, n in sorted(lengths.items()) if n > MAX_LINES} == {}


def _has_main_block(path: Path) -> bool:
    """Whether the module runs code under ``if __name__ == "__main__":``."""
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.If) and isinstance(node.test, ast.Compare):
            sides = [node.test.left, *node.test.comparators]
            if any(isinstance(side, ast.Name) and side.id == "__name__" for side in sides):
                return True
    return False


def test_the_command_line_is_the_package_s_one_entry_point() -> None:
    """One command line (Typer's ``pushctl``): no module of the package is a script of its
    own, and the one ``__main__.py`` is the command line's (``python -m pushctl.cli``)."""
    mains = sorted(path.relative_to(ROOT).as_posix() for path in PACKAGE.rglob("__main__.py"))
    assert mains == [COMMAND_LINE_MAIN.relative_to(ROOT).as_posix()]
    scripts = sorted(
        path.relative_to(ROOT).as_posix() for path in PACKAGE.rglob("*.py") if _has_main_block(path)
    )
    assert scripts == []


def test_a_main_block_is_found() -> None:
    assert _has_main_block(ROOT / "benchmarks" / "suite.py")
    assert not _has_main_block(PACKAGE / "cli" / "reproduce.py")


def test_the_command_line_loads_no_heavy_library_until_a_command_runs() -> None:
    """``pushctl --help`` imports the command modules only: their work (torch, matplotlib,
    pandas, Ray, MuJoCo) lives in the ``*_steps`` modules, imported when a command runs."""
    import subprocess
    import sys

    code = (
        "import sys, pushctl.cli.commands\n"
        "heavy = ('torch', 'matplotlib', 'pandas', 'ray', 'mujoco', 'pushctl.evaluation')\n"
        "print(','.join(m for m in heavy if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True
    )
    assert done.stdout.strip() == ""


def _third_party_importers(name: str) -> set[str]:
    """The pushctl subpackages (or top-level modules) whose source imports ``name``."""
    found = set()
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                modules = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                modules = [node.module]
            else:
                continue
            if any(module.split(".")[0] == name for module in modules):
                found.add(path.relative_to(PACKAGE).parts[0])
    return found


def test_pinocchio_has_one_importer() -> None:
    """arm/ is the only Pinocchio importer (docs: README's layout): the compiled library
    (native/) gets the model as Pinocchio's own serialisation and finds the wheel's files
    without importing it."""
    assert _third_party_importers("pinocchio") == {"arm"}
