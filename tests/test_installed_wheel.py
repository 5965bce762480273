"""The installed package needs nothing from the checkout: a wheel built from it, installed
without the checkout beside it and run from another directory, simulates and evaluates with
its shipped defaults, and ``gymnasium.make("pushctl/Push-v1")`` works after ``import
pushctl`` in either order with ``import gymnasium``.

The wheel goes into a directory of its own (``pip install --target``) that comes first on
the path of every command run here; the libraries it needs are the test environment's.
The first command compiles the simulator's kernels for that copy (about a minute)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _run(args: list[str], cwd: Path, site: Path) -> str:
    env = {**os.environ, "PYTHONPATH": str(site)}
    done = subprocess.run(
        [sys.executable, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=900
    )
    assert done.returncode == 0, (done.stdout + done.stderr)[-3000:]
    return done.stdout


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(the directory the wheel is installed in, an empty working directory)."""
    scratch = tmp_path_factory.mktemp("wheel")
    source, wheels = scratch / "source", scratch / "wheels"
    site, work = scratch / "site", scratch / "work"
    work.mkdir()
    source.mkdir()  # the build writes beside its sources: a copy keeps the checkout clean
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy2(ROOT / name, source / name)
    shutil.copytree(
        ROOT / "pushctl", source / "pushctl", ignore=shutil.ignore_patterns("__pycache__", "lib")
    )
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q"]
    build = [*pip, "wheel", str(source), "--no-deps", "--no-build-isolation", "-w", str(wheels)]
    subprocess.run(build, check=True, capture_output=True, timeout=600)
    (wheel,) = wheels.glob("pushctl-*.whl")
    subprocess.run(
        [*pip, "install", "--no-deps", "--target", str(site), str(wheel)],
        check=True, capture_output=True, timeout=600,
    )  # fmt: skip
    return site, work


def test_the_installed_copy_is_the_one_imported(installed: tuple[Path, Path]) -> None:
    site, work = installed
    where = _run(["-c", "import pushctl; print(pushctl.__file__)"], work, site)
    assert Path(where.strip()).is_relative_to(site)


def test_simulate_and_evaluate_run_on_the_shipped_defaults(installed: tuple[Path, Path]) -> None:
    site, work = installed
    cli = ["-m", "pushctl.cli"]
    simulate = [*cli, "simulate", "--controller", "feedback", "--scenario", "0"]
    _run([*simulate, "--duration", "1", "--out", "push.csv"], work, site)
    evaluate = [*cli, "evaluate", "--controller", "feedback", "--object", "cube"]
    evaluate += ["--profile", "constant", "--trials", "1", "--plant", "sim", "--out", "eval"]
    _run(evaluate, work, site)
    assert (work / "push.csv").is_file() and (work / "eval" / "trials.csv").is_file()
    assert not (work / "experiments").exists()


@pytest.mark.parametrize("imports", ["import pushctl, gymnasium", "import gymnasium, pushctl"])
def test_the_registered_env_is_made_after_either_import_order(
    installed: tuple[Path, Path], imports: str
) -> None:
    site, work = installed
    code = f"{imports}; print(gymnasium.make('pushctl/Push-v1').spec.id)"
    assert _run(["-c", code], work, site).strip().splitlines()[-1] == "pushctl/Push-v1"
