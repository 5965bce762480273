"""``pushctl train --seeds``: one Ray task per seed, each run the same as a single-seed run
with that seed, resumable per seed; and its bad input."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from functools import partial
from pathlib import Path

import pandas as pd
import pytest
import torch
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.control.gains import load_gains
from pushctl.errors import ConfigError
from pushctl.rl.presets import load_preset
from pushctl.rl.train import CHECKPOINT, CURVE, POLICY, Trainer, read_checkpoint
from pushctl.runs.seeds import (
    TIMING,
    CorePlan,
    SeedStatus,
    TrainJob,
    core_plan,
    parse_seeds,
    run_job,
    unfinished,
)

runner = CliRunner()


@pytest.fixture
def tiny(write_tiny_preset) -> str:
    return str(write_tiny_preset(episodes=4, pd_every=2, validate_every=2))


def _body(path: Path) -> str:
    """A CSV without its provenance line (which names the command)."""
    lines = path.read_text().splitlines(True)
    return "".join(line for line in lines if line.strip() and not line.startswith("#"))


def _actor(run: Path) -> dict[str, torch.Tensor]:
    return read_checkpoint(run / CHECKPOINT)["agent"]["actor"]


@pytest.mark.parametrize(
    ("text", "seeds"),
    [("0,1,2", (0, 1, 2)), ("0-4", (0, 1, 2, 3, 4)), ("3", (3,)), (" 2-3, 7 ", (2, 3, 7))],
)
def test_seed_lists_and_ranges(text: str, seeds: tuple[int, ...]) -> None:
    assert parse_seeds(text) == seeds


@pytest.mark.parametrize("text", ["", "a", "1,,2", "-1", "3-1", "1,1", "0-2,2", "1.5"])
def test_bad_seed_lists_are_refused(text: str) -> None:
    with pytest.raises(ConfigError, match="--seeds"):
        parse_seeds(text)


def test_each_seed_runs_as_a_single_seed_run_would(
    tiny: str, tmp_path: Path, ray_local: None
) -> None:
    out = tmp_path / "runs"
    result = runner.invoke(
        app, ["train", "--preset", tiny, "--seeds", "0,1", "--episodes", "3", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["seed-0", "seed-1"]
    for seed in (0, 1):
        run = out / f"seed-{seed}"
        assert (run / POLICY).is_file()
        assert read_checkpoint(run / CHECKPOINT)["next_episode"] == 3
        assert f"seed {seed} (training stream)" in (run / CURVE).read_text().splitlines()[0]
        alone = Trainer.start(load_preset(tiny), seed, tmp_path / f"alone-{seed}")
        alone.run(3, made_by="# made by: test")
        assert _body(run / CURVE) == _body(alone.out / CURVE)
        timing = json.loads((run / TIMING).read_text())  # the seed's own wall time
        assert timing["sessions"] == 1 and timing["episodes"] == 3 and timing["seconds"] > 0
    # The two seeds drew different scenarios.
    curves = [pd.read_csv(out / f"seed-{s}" / CURVE, comment="#") for s in (0, 1)]
    assert not curves[0]["rl_force_error"].equals(curves[1]["rl_force_error"])

    # Resumed per seed: one seed's run removed, both continue to 4 episodes (a run keeps
    # its own 3 unless --episodes asks for more).
    for name in (CHECKPOINT, CURVE, POLICY, "policy_last.pt", "validation.csv", TIMING):
        (out / "seed-1" / name).unlink()
    resumed = runner.invoke(
        app,
        ["train", "--preset", tiny, "--seeds", "0-1", "--resume", "--episodes", "4",
         "--out", str(out)],
    )  # fmt: skip
    assert resumed.exit_code == 0, resumed.output
    for seed in (0, 1):
        straight = Trainer.start(load_preset(tiny), seed, tmp_path / f"straight-{seed}")
        straight.run(4, made_by="# made by: test")
        run = out / f"seed-{seed}"
        assert read_checkpoint(run / CHECKPOINT)["next_episode"] == 4
        expected = straight.agent.state_dict()["actor"]
        for key, value in _actor(run).items():
            assert torch.equal(value, expected[key]), (seed, key)


@pytest.mark.parametrize(
    ("cores", "seeds", "plan"),
    [
        (2, 1, CorePlan(cpus=0.0, collectors=2)),  # one seed: its collectors on both cores
        (8, 2, CorePlan(cpus=0.0, collectors=2)),  # no more collectors than the preset's
        (4, 2, CorePlan(cpus=0.0, collectors=2)),
        (2, 2, CorePlan(cpus=1.0, collectors=0)),  # a core each
        (2, 3, CorePlan(cpus=2 / 3, collectors=0)),  # all three at once, no core left idle
        (2, 4, CorePlan(cpus=0.5, collectors=0)),
        (2, 5, CorePlan(cpus=1.0, collectors=0)),  # more: one core each, in turn
        (2, 0, CorePlan(cpus=0.0, collectors=2)),
    ],
)
def test_the_cores_are_shared_among_the_unfinished_seeds(
    cores: float, seeds: int, plan: CorePlan
) -> None:
    assert core_plan(cores, seeds, workers=2) == plan


def test_a_seed_alone_runs_its_collectors_to_the_same_run(
    write_tiny_preset, tmp_path: Path, ray_local: None
) -> None:
    """One seed on two cores: its task's learner runs the preset's two collectors as Ray
    actors (a task holding a core would leave them one), to the bytes of a run without
    them; a finished seed then counts for none of the cores."""
    preset = str(write_tiny_preset(episodes=3, pd_every=2, validate_every=2, workers=2))
    out = tmp_path / "runs"
    result = runner.invoke(app, ["train", "--preset", preset, "--out", str(out), "--seeds", "0"])
    assert result.exit_code == 0, result.output
    alone = Trainer.start(load_preset(preset), 0, tmp_path / "alone")
    alone.collectors = 0
    alone.run(3, made_by="# made by: test")
    assert _body(out / "seed-0" / CURVE) == _body(alone.out / CURVE)
    job = partial(TrainJob, load_preset(preset), episodes=None, made_by="", gains=load_gains())
    assert not unfinished(job(seed=0, out=out / "seed-0"))
    assert unfinished(job(seed=1, out=out / "seed-1"))


def test_run_job_resumes_the_checkpoint_it_finds(tiny: str, tmp_path: Path) -> None:
    job = TrainJob(load_preset(tiny), 5, tmp_path / "run", 2, "# made by: test", load_gains())
    first, _ = run_job(job)
    assert first.episodes == 2
    again, score = run_job(
        TrainJob(job.preset, 5, job.out, 4, job.made_by, job.gains), finish=lambda t: t.seed
    )
    assert (again.episodes, score) == (4, 5)
    other = TrainJob(job.preset, 6, job.out, 4, job.made_by, job.gains)
    with pytest.raises(ConfigError, match="seed 5"):
        run_job(other)


def test_a_stopped_session_counts_in_the_seed_training_time(tiny: str, tmp_path: Path) -> None:
    """timing.json is rewritten after every episode, so a session stopped mid-run (here by
    its progress callback raising after the first episode) still counts; the session that
    finishes the run adds its own."""
    job = TrainJob(load_preset(tiny), 5, tmp_path / "run", 3, "# made by: test", load_gains())

    def stop(name: str, status: SeedStatus) -> None:
        if status.done >= 1 and status.rates:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_job(job, report=stop)
    stopped = json.loads((job.out / TIMING).read_text())
    assert stopped["sessions"] == 1 and stopped["episodes"] == 1 and stopped["seconds"] > 0
    assert unfinished(job)
    run_job(job)
    finished = json.loads((job.out / TIMING).read_text())
    assert finished["sessions"] == 2 and finished["episodes"] == 3
    assert finished["seconds"] > stopped["seconds"]
    assert not unfinished(job)


def _one_line_error(result, *fragments: str) -> None:
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    for fragment in fragments:
        assert fragment in lines[0]


def test_bad_seed_options_give_one_line_errors(tiny: str, tmp_path: Path) -> None:
    out = str(tmp_path / "runs")
    base = ["train", "--preset", tiny, "--out", out]
    _one_line_error(runner.invoke(app, [*base, "--seeds", "0,1", "--seed", "2"]), "exclude")
    _one_line_error(runner.invoke(app, [*base, "--seeds", "2-0"]), "backwards")
    _one_line_error(runner.invoke(app, [*base, "--seeds", "x"]), "0-4")
    _one_line_error(runner.invoke(app, [*base, "--address", "auto"]), "--seeds")
    occupied = tmp_path / "runs" / "seed-1"
    occupied.mkdir(parents=True)
    (occupied / "notes.txt").write_text("keep me")
    _one_line_error(runner.invoke(app, [*base, "--seeds", "0,1"]), "seed-1", "--resume")
    _one_line_error(runner.invoke(app, [*base, "--seeds", "0,1", "--resume"]), "no checkpoint")
    assert (occupied / "notes.txt").read_text() == "keep me"
    assert not (tmp_path / "runs" / "seed-0").exists()


def _parent(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, ValueError, IndexError):
        return 0


def _task_processes(ancestor: int) -> list[int]:
    """Ray worker processes below ``ancestor`` (its Ray instance's, not another one's on
    this machine) running a seed's training task (Ray titles them ``ray::_task``)."""
    found = []
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            if not cmdline.read_bytes().startswith(b"ray::_task"):
                continue
        except OSError:
            continue
        pid = int(cmdline.parent.name)
        while pid > 1 and pid != ancestor:
            pid = _parent(pid)
        if pid == ancestor:
            found.append(int(cmdline.parent.name))
    return found


def test_a_killed_worker_is_retried_from_its_checkpoint(tiny: str, tmp_path: Path) -> None:
    """kill -9 to the worker process training a seed: Ray reruns the task, which continues
    from the last checkpoint (never from an earlier episode) to the run a worker that was
    never killed writes."""
    out = tmp_path / "runs"
    command = [sys.executable, "-m", "pushctl.cli", "train", "--preset", tiny, "--seeds", "3"]
    process = subprocess.Popen(
        [*command, "--episodes", "8", "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    checkpoint = out / "seed-3" / CHECKPOINT
    deadline = time.monotonic() + 120
    while not checkpoint.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    workers = _task_processes(process.pid)
    assert len(workers) == 1, workers
    os.kill(workers[0], signal.SIGKILL)
    killed_at = read_checkpoint(checkpoint)["next_episode"]
    assert 2 <= killed_at < 8
    seen = []
    while process.poll() is None:
        seen.append(read_checkpoint(checkpoint)["next_episode"])
        time.sleep(0.1)
    assert process.returncode == 0, process.stderr.read() if process.stderr else ""
    assert min(seen) >= killed_at  # resumed, not started over
    straight = Trainer.start(load_preset(tiny), 3, tmp_path / "straight")
    made_by = (out / "seed-3" / CURVE).read_text().splitlines()[0]
    straight.run(8, made_by=made_by)
    for name in (CURVE, "validation.csv"):
        assert (out / "seed-3" / name).read_bytes() == (straight.out / name).read_bytes()
    expected = straight.agent.state_dict()["actor"]
    for key, value in _actor(out / "seed-3").items():
        assert torch.equal(value, expected[key]), key


def test_an_address_where_no_cluster_answers_is_a_one_line_error() -> None:
    from pushctl.distributed.engine import connect

    clock = time.monotonic()
    with pytest.raises(ConfigError, match="no Ray cluster answers") as caught:
        connect("127.0.0.1:1")
    assert "\n" not in str(caught.value) and time.monotonic() - clock < 10


def test_address_joins_a_running_cluster(tiny: str, tmp_path: Path, ray_local: None) -> None:
    """This test session's Ray instance stands in for a cluster: a ``pushctl train`` process
    joins it with ``--address`` and its seed runs there."""
    import ray

    address = ray.get_runtime_context().gcs_address
    command = [sys.executable, "-m", "pushctl.cli", "train", "--preset", tiny, "--episodes", "1"]
    joined = subprocess.run(
        [*command, "--seeds", "0", "--out", str(tmp_path / "a"), "--address", address],
        capture_output=True,
        text=True,
    )
    assert joined.returncode == 0, joined.stderr
    assert read_checkpoint(tmp_path / "a" / "seed-0" / CHECKPOINT)["next_episode"] == 1


def test_the_address_comes_from_the_option_then_ray_address(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from pushctl.distributed.engine import address_from

    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    assert address_from(None) is None  # start Ray here
    monkeypatch.setenv("RAY_ADDRESS", "head:6379")
    assert address_from(None) == "head:6379"
    assert address_from("other:6379") == "other:6379"
