"""The package's layout shows its architecture: no import cycle between pushctl's modules,
imports flowing one way through the layers, and a top level holding only the shared basics.

The import graph is read from the source with :mod:`ast` (every ``import`` statement,
including those inside functions and under ``TYPE_CHECKING``: a deferred import is still a
dependency), so the test needs no import of the package.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "pushctl"

TOP_LEVEL = {
    "__init__.py",
    "types.py",
    "errors.py",
    "config.py",
    # the shared helpers: argument checks, provenance lines and atomic writes, the refusal
    # to overwrite results, reading TOML files
    "checks.py",
    "provenance.py",
    "output_guard.py",
    "toml_files.py",
    "proxqp_build.py",  # ProxQP from its portable build, for planning and contact alike
    "machine.py",  # the kind of machine a run's last bits belong to (its manifest says)
    "kernel_cache.py",  # numba's cached kernels dropped when a file they compile in changed
}

# Layer of each subpackage (and of the few modules that sit above their package's layer):
# a module may import only modules of its own layer or lower. cli → evaluation / rl →
# episode → control / planning → contact → arm / objects, with the shared basics below all.
LAYERS = {
    "pushctl.cli": 9,
    "pushctl.bench": 9,
    "pushctl.report": 8,  # tables and figures from the evaluation's results
    "pushctl.mujoco.transfer": 8,  # a study: the evaluation on MuJoCo beside the report's
    "pushctl.distributed.seeds": 7,  # several training runs on Ray
    "pushctl.distributed.sweep": 7,
    "pushctl.distributed.sweep_config": 7,
    "pushctl.evaluation": 6,
    "pushctl.realdata": 6,  # recorded pushes replayed and scored
    "pushctl.rl": 5,
    "pushctl.episode": 4,
    "pushctl.mujoco.validation": 4,  # a study: our world against MuJoCo in episodes
    "pushctl.control": 3,
    "pushctl.planning": 3,
    "pushctl.contact": 2,
    "pushctl.kinematic": 2,  # a pusher on a prescribed path: the contact step, no arm
    "pushctl.mujoco": 2,  # the other engine: a peer of contact (pushctl.contact.build picks)
    "pushctl.arm": 1,
    "pushctl.objects": 1,
    "pushctl.distributed.engine": 0,  # the Ray session and worker pool: infrastructure
    "pushctl.native": 0,  # the compiled library (Pinocchio's, ProxSuite's calls): no pushctl
    "pushctl.types": 0,
    "pushctl.errors": 0,
    "pushctl.config": 0,
    "pushctl.checks": 0,
    "pushctl.provenance": 0,
    "pushctl.output_guard": 0,
    "pushctl.toml_files": 0,
    "pushctl.proxqp_build": 0,
    "pushctl.machine": 0,
    "pushctl.kernel_cache": 0,
}


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
    """The layer of ``module``: its own entry, else its closest package's."""
    name = module
    while name:
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
        if module == "pushctl":
            continue  # the public API: it re-exports from below and registers Push-v0
        for target in targets:
            if target == "pushctl":
                continue  # ``import pushctl`` for __version__; covered by the cycle test
            assert layer(module) is not None, f"{module} has no layer in LAYERS"
            assert layer(target) is not None, f"{target} has no layer in LAYERS"
            if layer(target) > layer(module):
                upward.append(f"{module} (layer {layer(module)}) imports {target} "
                              f"(layer {layer(target)})")  # fmt: skip
    assert upward == []


def test_the_core_never_imports_the_command_line() -> None:
    for module, targets in import_graph().items():
        if module.startswith(("pushctl.cli", "pushctl.bench")):
            continue
        assert not {t for t in targets if t.startswith(("pushctl.cli", "pushctl.bench"))}, module


def test_top_level_holds_only_the_shared_basics() -> None:
    files = {p.name for p in PACKAGE.iterdir() if p.suffix == ".py"}
    assert files == TOP_LEVEL


@pytest.mark.parametrize("package", ["cli", "bench"])
def test_command_line_and_benchmarks_are_packages(package: str) -> None:
    assert (PACKAGE / package / "__init__.py").is_file()
    assert (PACKAGE / package / "__main__.py").is_file()  # python -m pushctl.cli / .bench


def test_the_command_line_loads_no_heavy_library_until_a_command_runs() -> None:
    """``pushctl --help`` imports the command modules only: their work (torch, matplotlib,
    pandas, Ray, MuJoCo) lives in the ``*_steps`` modules, imported when a command runs."""
    import subprocess
    import sys

    code = (
        "import sys, pushctl.cli\n"
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
