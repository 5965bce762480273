"""Nothing lost under faults: a tiny training run killed at every kind of moment and resumed
ends with the bytes of an uninterrupted run; two writers, a full disk, damaged files and
SIGTERM each end in one line, with the earlier good files intact.

What "the same bytes" compares: the data rows of ``curve.csv`` and ``validation.csv`` and
the content of ``policy.pt``/``policy_last.pt`` (the actor's tensors and the env settings).
Their provenance lines differ by design: a resumed run's line names the resume too.
"""

from __future__ import annotations

import errno
import os
import random
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import torch
from fault_helpers import lock_held_elsewhere, one_error_line, recorded_pushes
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.errors import ConfigError
from pushctl.files.output_guard import LOCK_NAME
from pushctl.rl import train as train_module
from pushctl.rl.checkpoint import content_digest, load_checked
from pushctl.rl.presets import load_preset
from pushctl.rl.train import CHECKPOINT, CURVE, LAST_POLICY, POLICY, VALIDATION, Trainer

TINY = """
[train]
episodes = 4
checkpoint_every = 2
pd_every = 2
workers = 0
validate_every = 2
validation_per_cell = 1

[env]
objects = ["cube"]
profiles = ["constant"]
duration = 1.0
gate_threshold = 0.0

[ddpg]
hidden = [8, 8]
batch_size = 16
buffer_size = 1000
warmup_steps = 60
updates_per_step = 0.05
reward_scale = 100.0
"""
EPISODES = 4
runner = CliRunner()


@pytest.fixture(scope="module")
def preset_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("preset") / "tiny.toml"
    path.write_text(TINY)
    return path


@pytest.fixture(scope="module")
def reference(preset_file, tmp_path_factory) -> dict[str, object]:
    """The uninterrupted run's results."""
    out = tmp_path_factory.mktemp("reference") / "run"
    Trainer.start(load_preset(str(preset_file)), 0, out).run(EPISODES)
    return results(out)


def results(out: Path) -> dict[str, object]:
    """What must not differ between an interrupted-and-resumed run and an uninterrupted one."""
    found: dict[str, object] = {}
    for name in (CURVE, VALIDATION):
        text = (out / name).read_text()  # rows, not the provenance and digest lines
        found[name] = "".join(r for r in text.splitlines(True) if r.strip() and r[0] != "#")
    for name in (POLICY, LAST_POLICY):
        state = load_checked(out / name, "policy file")
        found[name] = content_digest({"actor": state["actor"], "env": state["env"]})
    return found


class Killed(BaseException):
    """Stands for the process dying at that moment (nothing after it runs)."""


def _resume_to_end(out: Path) -> None:
    trainer = Trainer.resume(out)
    assert not trainer.finished(EPISODES)
    trainer.run(EPISODES)
    assert Trainer.resume(out).finished(EPISODES)


def test_killed_mid_episode_resumes_to_the_same_bytes(preset_file, reference, tmp_path):
    out = tmp_path / "run"
    kill_after = random.Random(os.getpid()).choice([1, 2, 3])  # the checkpoint follows 2

    def die(progress):
        if progress.episodes_done == kill_after:
            raise Killed

    with pytest.raises(Killed):
        Trainer.start(load_preset(str(preset_file)), 0, out).run(EPISODES, on_episode=die)
    if (out / CHECKPOINT).exists():
        _resume_to_end(out)
    else:  # killed before the first checkpoint: nothing kept, the same command starts over
        assert not (out / CURVE).exists()
        result = runner.invoke(app, ["train", "--preset", str(preset_file), "--out", str(out)])
        assert result.exit_code == 0, result.output
    assert results(out) == reference


def test_killed_mid_checkpoint_leaves_the_old_one_and_a_swept_folder(
    preset_file, reference, tmp_path, monkeypatch
):
    out = tmp_path / "run"
    real_save = torch.save
    calls = []

    def save_then_die(state, target):
        calls.append(target)
        if len(calls) == 2:  # the second checkpoint: half written, then the process dies
            Path(target).write_bytes(b"PK\x03\x04 half a zip")
            raise Killed
        real_save(state, target)

    monkeypatch.setattr(torch, "save", save_then_die)
    with pytest.raises(Killed):
        Trainer.start(load_preset(str(preset_file)), 0, out).run(EPISODES)
    monkeypatch.setattr(torch, "save", real_save)
    # the process died in its write: its temporary folder is left, under a dead pid's name
    left = out / f".{CHECKPOINT}.{os.getpid()}.tmp"
    dead = out / f".{CHECKPOINT}.999999.tmp"
    if left.exists():
        left.rename(dead)
    else:
        (dead).mkdir()
        (dead / CHECKPOINT).write_bytes(b"PK partial")
    assert Trainer.resume(out).next_episode == 2  # the first checkpoint, intact
    result = runner.invoke(app, ["train", "--resume", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert not dead.exists()  # swept by the next command holding the directory
    assert results(out) == reference


def test_killed_after_the_last_checkpoint_ships_its_policy(
    preset_file, reference, tmp_path, monkeypatch
):
    out = tmp_path / "run"

    def die(*args, **kwargs):
        raise Killed

    # the final validation and the policies are what runs after the last checkpoint
    monkeypatch.setattr(train_module, "write_policy", die)
    with pytest.raises(Killed):
        Trainer.start(load_preset(str(preset_file)), 0, out).run(EPISODES)
    monkeypatch.undo()
    assert not (out / POLICY).exists()
    result = runner.invoke(app, ["train", "--resume", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "nothing to do" not in result.output
    assert (out / POLICY).is_file() and (out / LAST_POLICY).is_file()
    assert results(out) == reference
    again = runner.invoke(app, ["train", "--resume", "--out", str(out)])
    assert "nothing to do" in again.output  # now it is finished


def test_an_extended_run_killed_after_its_last_checkpoint_replaces_its_policies(
    preset_file, reference, tmp_path, monkeypatch
):
    out = tmp_path / "run"
    Trainer.start(load_preset(str(preset_file)), 0, out).run(2)
    short = {name: (out / name).read_bytes() for name in (POLICY, LAST_POLICY)}

    def die(*args, **kwargs):
        raise Killed

    monkeypatch.setattr(train_module, "write_policy", die)
    with pytest.raises(Killed):  # extended to 4, killed after its checkpoint at 4
        Trainer.resume(out).run(EPISODES)
    monkeypatch.undo()
    assert {name: (out / name).read_bytes() for name in short} == short  # the 2-episode ones
    assert not Trainer.resume(out).finished(EPISODES)
    result = runner.invoke(app, ["train", "--resume", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "nothing to do" not in result.output
    assert results(out) == reference


def test_a_bare_resume_keeps_the_runs_own_episodes(preset_file, tmp_path):
    out = tmp_path / "run"
    train = ["train", "--preset", str(preset_file), "--out", str(out)]
    first = runner.invoke(app, [*train, "--episodes", "2"])
    assert first.exit_code == 0, first.output
    policy = (out / POLICY).read_bytes()
    again = runner.invoke(app, ["train", "--resume", "--out", str(out)])
    assert again.exit_code == 0, again.output
    assert "already has 2 episodes; nothing to do" in " ".join(again.output.split())
    assert (out / POLICY).read_bytes() == policy


def test_the_resume_hint_trains_to_the_episodes_asked_for(preset_file, tmp_path, monkeypatch):
    out = tmp_path / "run"
    real_run = Trainer.run

    def interrupted_after_the_checkpoint(self, episodes, on_episode=None, made_by=""):
        def stop(progress):
            on_episode(progress)
            if progress.episodes_done == 3:  # after the checkpoint at 2
                raise KeyboardInterrupt

        real_run(self, episodes, on_episode=stop, made_by=made_by)

    monkeypatch.setattr(Trainer, "run", interrupted_after_the_checkpoint)
    train = ["train", "--preset", str(preset_file), "--episodes", "3", "--out", str(out)]
    stopped = runner.invoke(app, train)
    assert stopped.exit_code == 130, stopped.output
    monkeypatch.undo()
    hint = stopped.stderr.split("`")[1]
    assert hint.startswith("pushctl train --resume") and "--episodes 3" in hint
    resumed = runner.invoke(app, shlex.split(hint)[1:])
    assert resumed.exit_code == 0, resumed.output
    assert Trainer.resume(out).next_episode == 3  # not the preset's 4


def test_a_second_writer_is_refused_while_the_first_holds_the_directory(tmp_path):
    out = tmp_path / "evaluation"
    out.mkdir()
    args = ["evaluate", "--object", "cube", "--profile", "chirp", "--trials", "1",
            "--controller", "pd", "--plant", "sim", "--out", str(out)]  # fmt: skip
    with lock_held_elsewhere(out / LOCK_NAME):
        one_error_line(runner.invoke(app, args), str(out), "in use by another pushctl command")
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]  # nothing written
        train = ["train", "--out", str(out)]
        one_error_line(runner.invoke(app, train), "in use")
    done = runner.invoke(app, args)
    assert done.exit_code == 0, done.output
    assert sorted(p.name for p in out.iterdir()) == ["steps.csv", "trials.csv"]


def test_a_second_sac_trainer_is_refused_while_the_first_holds_the_directory(tmp_path):
    out = tmp_path / "sac"
    out.mkdir()
    sac = ["train", "--algo", "sb3-sac", "--episodes", "1", "--out", str(out)]
    with lock_held_elsewhere(out / LOCK_NAME):
        one_error_line(runner.invoke(app, sac), str(out), "in use by another pushctl command")
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]  # nothing written


def test_a_full_disk_during_training_is_one_line_and_keeps_the_checkpoint(
    preset_file, tmp_path, monkeypatch
):
    out = tmp_path / "run"
    first = runner.invoke(app, ["train", "--preset", str(preset_file), "--episodes", "2",
                                "--out", str(out)])  # fmt: skip
    assert first.exit_code == 0, first.output
    before = (out / CHECKPOINT).read_bytes()

    def full(state, target):
        Path(target).write_bytes(b"PK")
        raise RuntimeError("[enforce fail at inline_container.cc:603] . unexpected pos 1088")

    monkeypatch.setattr(torch, "save", full)
    monkeypatch.setattr("shutil.disk_usage", lambda path: type("Usage", (), {"free": 0})())
    result = runner.invoke(app, ["train", "--resume", "--episodes", "4", "--out", str(out)])
    line = one_error_line(result, f"cannot write {out / CHECKPOINT}", "No space left")
    assert ".tmp" not in line
    assert (out / CHECKPOINT).read_bytes() == before
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]


def test_a_full_disk_while_writing_a_csv_names_the_file(tmp_path, monkeypatch):
    import pandas as pd

    def no_space(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(pd.DataFrame, "to_csv", no_space)
    out = tmp_path / "evaluation"
    args = ["evaluate", "--object", "cube", "--profile", "chirp", "--trials", "1",
            "--controller", "pd", "--plant", "sim", "--out", str(out)]  # fmt: skip
    one_error_line(runner.invoke(app, args), f"cannot write {out}", "No space left on device")
    assert not out.exists() or not list(out.iterdir())


def fill_the_disk(monkeypatch) -> None:
    """From now on no space is left: writing a lock file's process id, a file's bytes or a
    torch file fails as on a full disk."""
    real_write = os.write

    def write(descriptor, data):
        try:
            target = os.readlink(f"/proc/self/fd/{descriptor}")
        except OSError:
            target = ""
        if target.endswith(".lock"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_write(descriptor, data)

    def no_space(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", write)
    monkeypatch.setattr(Path, "write_bytes", no_space)
    monkeypatch.setattr(torch, "save", no_space)


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="reads /proc")
@pytest.mark.parametrize("command", ["plan", "train", "report"])
def test_a_full_disk_is_one_line_naming_the_file(command, preset_file, tmp_path, monkeypatch):
    from synthetic_results import write_results

    out = tmp_path / "out"
    results_dir = write_results(tmp_path / "results")
    args, target = {
        "plan": (["plan", "--object", "cube", "--goal", "0.6,0,0", "--out", str(out / "p.csv")],
                 out / "p.csv"),
        "train": (["train", "--preset", str(preset_file), "--episodes", "2", "--out", str(out)],
                  out / CHECKPOINT),
        "report": (["report", "--in", str(results_dir), "--out", str(out)], out / "table3.csv"),
    }[command]  # fmt: skip
    out.mkdir()
    fill_the_disk(monkeypatch)
    one_error_line(runner.invoke(app, args), f"cannot write {target}", "No space left on device")


@pytest.mark.parametrize("which", [CHECKPOINT, POLICY])
def test_flipped_bytes_and_edited_weights_are_refused(preset_file, reference, tmp_path, which):
    out = tmp_path / "run"
    Trainer.start(load_preset(str(preset_file)), 0, out).run(2)
    path = out / which
    data = bytearray(path.read_bytes())
    rng = random.Random(3)
    for _ in range(16):
        at = rng.randrange(len(data) // 4, len(data) - 200)
        data[at] ^= 0xFF
    good = path.read_bytes()
    path.write_bytes(bytes(data))
    with pytest.raises(ConfigError, match="damaged|corrupt|not a"):
        load_checked(path, which)
    # loaded, changed and saved again with valid zip checksums: the digest catches it
    state = torch.load(_write(tmp_path / "good.pt", good), weights_only=True)
    tensors = state["agent"]["actor"] if which == CHECKPOINT else state["actor"]["actor"]
    first = next(iter(tensors))
    tensors[first] = tensors[first] * 1e26
    torch.save(state, path)
    with pytest.raises(ConfigError, match="changed after it was written"):
        load_checked(path, which)
    command = (["train", "--resume", "--out", str(out)] if which == CHECKPOINT else
               ["evaluate", "--controller", "rl", "--trials", "1", "--object", "cube",
                "--profile", "chirp", "--plant", "sim", "--policy", str(path),
                "--out", str(tmp_path / "eval")])  # fmt: skip
    one_error_line(runner.invoke(app, command), str(path))


@pytest.mark.parametrize("which", [CHECKPOINT, POLICY, "trials.csv"])
def test_a_file_whose_digest_was_removed_is_refused_unless_trusted(preset_file, tmp_path, which):
    """Its digest removed and its content edited: refused in one line naming the file and
    --trust-undigested; with that option the command runs."""
    from synthetic_results import write_results

    if which == "trials.csv":
        root = write_results(tmp_path / "results")
        path = root / "evaluation" / "trials.csv"
        lines = [line for line in path.read_text().splitlines(True) if "sha256" not in line]
        lines[3] = lines[3].replace("0.", "9.", 1)
        path.write_text("".join(lines))
        command = ["report", "--in", str(root), "--out", str(tmp_path / "report")]
    else:
        out = tmp_path / "run"
        Trainer.start(load_preset(str(preset_file)), 0, out).run(2)
        path = out / which
        state = torch.load(path, weights_only=True)
        del state["digest"]
        tensors = state["agent"]["actor"] if which == CHECKPOINT else state["actor"]["actor"]
        first = next(iter(tensors))
        tensors[first] = tensors[first] * 1.5
        torch.save(state, path)
        command = (["train", "--resume", "--episodes", "3", "--out", str(out)]
                   if which == CHECKPOINT else
                   ["evaluate", "--controller", "rl", "--trials", "1", "--object", "cube",
                    "--profile", "chirp", "--plant", "sim", "--policy", str(path),
                    "--out", str(tmp_path / "eval")])  # fmt: skip
    one_error_line(runner.invoke(app, command), str(path), "--trust-undigested")
    trusted = runner.invoke(app, [*command, "--trust-undigested"])
    assert trusted.exit_code == 0, trusted.output


def _write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def test_a_trials_file_cut_at_a_line_boundary_is_refused(tmp_path):
    from synthetic_results import write_results

    root = write_results(tmp_path / "results")
    trials = root / "evaluation" / "trials.csv"
    lines = trials.read_text().splitlines(keepends=True)
    trials.write_text("".join(lines[: len(lines) - 5]))
    result = runner.invoke(app, ["report", "--in", str(root), "--out", str(tmp_path / "out")])
    one_error_line(result, str(trials), "cut short")
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())


@pytest.mark.parametrize("damage", ["edited-value", "line-dropped", "gzipped-edit"])
def test_a_results_file_that_does_not_match_its_digest_is_refused(tmp_path, damage):
    """A CSV pushctl wrote ends in the SHA-256 of its bytes: one edited value, a dropped
    row (the cells stay complete) or an edit inside the gzipped steps is refused in one line;
    the untouched file reports."""
    import gzip

    import pandas as pd
    from synthetic_results import write_results

    from pushctl.files.provenance import write_csv

    root = write_results(tmp_path / "results")
    trials = root / "evaluation" / "trials.csv"
    write_csv(trials, pd.read_csv(trials, comment="#"), "# made by: a test")
    steps = root / "evaluation" / "steps.csv"
    write_csv(steps, pd.read_csv(steps, comment="#"), "# made by: a test")
    ok = runner.invoke(app, ["report", "--in", str(root), "--out", str(tmp_path / "ok")])
    assert ok.exit_code == 0, ok.output
    target = trials
    lines = trials.read_text().splitlines(keepends=True)
    if damage == "edited-value":  # one digit of row 3's last field
        head, _, last = lines[3].rpartition(",")
        lines[3] = (
            f"{head},{last.replace(last.strip()[-1], '7' if last.strip()[-1] != '7' else '3')}"
        )
        trials.write_text("".join(lines))
    elif damage == "line-dropped":
        trials.write_text("".join([*lines[:-3], *lines[-2:]]))
    else:
        text = steps.read_text().splitlines(keepends=True)
        text[2] = text[2].replace("0", "5", 1) if "0" in text[2] else text[2].replace("1", "2", 1)
        target = steps.with_name("steps.csv.gz")
        target.write_bytes(gzip.compress("".join(text).encode()))
        steps.unlink()
    result = runner.invoke(app, ["report", "--in", str(root), "--out", str(tmp_path / "out")])
    one_error_line(result, str(target), "digest")
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").iterdir())


def _ray_processes_of(pid: int) -> list[str]:
    """Command lines of the processes whose parent chain reaches ``pid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            environ = (entry / "environ").read_bytes()
        except OSError:
            continue
        if f"PUSHCTL_FAULT_TEST={pid}".encode() in environ:
            found.append((entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()[:80])
    return found


def _spawn_train(preset_file: Path, out: Path, *extra: str) -> subprocess.Popen:
    env = {**os.environ, "PUSHCTL_FAULT_TEST": str(os.getpid())}
    return subprocess.Popen(
        [sys.executable, "-c", "from pushctl.cli import app; app()", "train",
         "--preset", str(preset_file), "--out", str(out), *extra],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
    )  # fmt: skip


@pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="reads /proc")
def test_sigterm_stops_training_cleanly_and_the_run_resumes(preset_file, reference, tmp_path):
    pytest.importorskip("ray")
    out = tmp_path / "run"
    process = _spawn_train(preset_file, out, "--workers", "1")  # a collector on Ray
    deadline = time.monotonic() + 240
    while not (out / CHECKPOINT).exists() and process.poll() is None:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    ray = [line for line in _ray_processes_of(os.getpid()) if "ray" in line.lower()]
    process.send_signal(signal.SIGTERM)
    stdout, stderr = process.communicate(timeout=60)
    if process.returncode == 0:
        pytest.skip("the run finished before the signal arrived")
    assert process.returncode == 143, stderr
    assert "Traceback" not in stderr and "Aborted" not in stderr
    # Ray's core worker logs, at its start, that it took its level from the environment
    lines = [line for line in stderr.splitlines() if line.strip() and "Set ray log" not in line]
    assert len(lines) == 1 and "--resume" in lines[0], stderr
    assert ray or process.returncode == 0, "Ray's processes were never seen: nothing checked"
    time.sleep(1.0)
    assert _ray_processes_of(os.getpid()) == []
    result = runner.invoke(app, ["train", "--resume", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert results(out) == reference


def test_sigterm_before_the_first_checkpoint_advises_starting_over(preset_file, tmp_path):
    out = tmp_path / "run"
    process = _spawn_train(preset_file, out)
    time.sleep(1.0)  # importing, before any episode
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode in (143, -signal.SIGTERM), stderr
    assert "Traceback" not in stderr
    if process.returncode == 143 and stderr.strip():
        assert "--resume" not in stderr or (out / CHECKPOINT).exists()
    # whatever was left, the same command runs again
    again = runner.invoke(app, ["train", "--preset", str(preset_file), "--out", str(out)])
    assert again.exit_code == 0, again.output


@pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="reads /proc")
def test_sigterm_during_a_replay_is_one_line_and_stops_its_workers(tmp_path):
    data = recorded_pushes(tmp_path / "data", 3000)
    env = {**os.environ, "PUSHCTL_FAULT_TEST": str(os.getpid())}
    process = subprocess.Popen(
        [sys.executable, "-m", "pushctl.cli", "realdata", "score", "--data", str(data),
         "--friction", str(data / "fit.toml"), "--out", str(tmp_path / "score"),
         "--workers", "2"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
        start_new_session=True,
    )  # fmt: skip
    deadline = time.monotonic() + 120
    while len(_ray_processes_of(os.getpid())) < 3 and process.poll() is None:  # and 2 workers
        assert time.monotonic() < deadline
        time.sleep(0.1)
    time.sleep(1.0)  # replaying
    os.killpg(process.pid, signal.SIGTERM)  # as a terminal or a batch system sends it
    _, stderr = process.communicate(timeout=30)
    assert process.returncode == 143, stderr
    assert "Traceback" not in stderr
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert lines == ["terminated: nothing written; run the command again"], stderr
    time.sleep(0.5)
    assert _ray_processes_of(os.getpid()) == []  # no worker left replaying
    assert not (tmp_path / "score").exists()
