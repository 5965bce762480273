"""Bad input, a table of it: flags, training presets, object and pusher files, gains, policy
and results files, paths. Every case ends in one ``error:`` line on stderr, exit code 2, no
traceback, and no file written anywhere (the working directory included)."""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest
import torch
from synthetic_results import write_results
from typer.testing import CliRunner

from pushctl.cli import app
from pushctl.rl.checkpoint import save_checked

runner = CliRunner()
SHIPPED_POLICY = Path(__file__).resolve().parents[2] / "results" / "training" / "policy.pt"

QUICK_PRESET = """
[train]
episodes = 2
[env]
objects = ["cube"]
[ddpg]
{ddpg}
"""
OBJECT = """mass = {mass}
height = 0.088
size = [{size}, 0.088]
"""
PUSHER = "n_prongs = {n}\nprong_spacing = {spacing}\nmass = {mass}\n"
GAINS = "[pd]\nkp = {kp}\nkv = {kv}\nkx_linear = 10.0\nkx_angular = 10.0\n"
GAINS += "ik_damping = 0.001\nposture_gain = 1.0\n"
GOAL = ["--goal", "0.62,0.03,30"]
EVAL = ["evaluate", "--object", "cube", "--profile", "chirp", "--trials", "1", "--plant", "sim"]
SIM = ["simulate", "--duration", "1", "--scenario", "1"]

# (id, arguments with {tmp} for the test's directory, files to write there first)
CASES: list[tuple[str, list[str], dict[str, object]]] = [
    # ---- flags
    ("plan-no-goal", ["plan"], {}),
    ("plan-goal-two-numbers", ["plan", "--goal", "0.6,0.1"], {}),
    ("plan-goal-words", ["plan", "--goal", "a,b,c"], {}),
    ("plan-goal-nan", ["plan", "--goal", "nan,0,0"], {}),
    ("plan-goal-inf", ["plan", "--goal", "inf,0,0"], {}),
    ("plan-goal-out-of-reach", ["plan", "--goal", "5,5,0"], {}),
    ("plan-duration-zero", ["plan", *GOAL, "--duration", "0"], {}),
    ("plan-duration-negative", ["plan", *GOAL, "--duration", "-3"], {}),
    ("plan-duration-text", ["plan", *GOAL, "--duration", "long"], {}),
    ("plan-dt-zero", ["plan", *GOAL, "--dt", "0"], {}),
    ("plan-dt-huge", ["plan", *GOAL, "--dt", "1e9"], {}),
    ("plan-mu-negative", ["plan", *GOAL, "--mu-contact", "-1"], {}),
    ("plan-mu-ground-nan", ["plan", *GOAL, "--mu-ground", "nan"], {}),
    ("plan-unknown-object", ["plan", *GOAL, "--object", "sphere"], {}),
    ("plan-unknown-profile", ["plan", *GOAL, "--profile", "zigzag"], {}),
    ("plan-unknown-arm", ["plan", *GOAL, "--arm", "ur5"], {}),
    ("plan-start-bad", ["plan", *GOAL, "--start", "1,2"], {}),
    ("evaluate-controller-twice", [*EVAL, "--controller", "pd", "--controller", "feedback"], {}),
    ("evaluate-plant-twice", [*EVAL, "--plant", "proxy"], {}),
    ("plan-unknown-option", ["plan", *GOAL, "--speed", "3"], {}),
    ("unknown-command", ["push"], {}),
    ("simulate-unknown-controller", [*SIM, "--controller", "mpc"], {}),
    ("simulate-unknown-plant", [*SIM, "--plant", "real"], {}),
    ("simulate-duration-zero", ["simulate", "--duration", "0"], {}),
    ("simulate-duration-nan", ["simulate", "--duration", "nan"], {}),
    ("simulate-scenario-negative", [*SIM, "--scenario", "-1"], {}),
    ("simulate-scenario-text", [*SIM, "--scenario", "one"], {}),
    ("simulate-mass-huge", [*SIM, "--object-mass", "1e12"], {}),
    ("simulate-mass-tiny", [*SIM, "--object-mass", "1e-9"], {}),
    ("simulate-mass-zero", [*SIM, "--object-mass", "0"], {}),
    ("simulate-mass-negative", [*SIM, "--object-mass", "-0.3"], {}),
    ("simulate-mass-nan", [*SIM, "--object-mass", "nan"], {}),
    ("simulate-mu-huge", [*SIM, "--mu-ground", "1e9"], {}),
    ("simulate-mu-negative", [*SIM, "--mu-contact", "-0.2"], {}),
    ("simulate-goal-bad", [*SIM, "--goal", "x"], {}),
    ("simulate-rl-no-policy-file", [*SIM, "--controller", "rl", "--policy", "{tmp}/no.pt"], {}),
    ("evaluate-trials-zero", [*EVAL, "--trials", "0"], {}),
    ("evaluate-trials-negative", [*EVAL, "--trials", "-5"], {}),
    ("evaluate-trials-text", [*EVAL, "--trials", "many"], {}),
    ("evaluate-workers-zero", [*EVAL, "--workers", "0"], {}),
    ("evaluate-workers-many", [*EVAL, "--workers", "999"], {}),
    ("evaluate-unknown-object", [*EVAL, "--object", "ball"], {}),
    ("evaluate-unknown-profile", [*EVAL, "--profile", "sine"], {}),
    ("evaluate-unknown-controller", [*EVAL, "--controller", "lqr"], {}),
    ("evaluate-unknown-plant", [*EVAL, "--plant", "robot"], {}),
    ("evaluate-unknown-stream", [*EVAL, "--stream", "test"], {}),
    ("evaluate-missing-policy", [*EVAL, "--controller", "rl", "--policy", "{tmp}/no.pt"], {}),
    ("evaluate-policy-is-dir", [*EVAL, "--controller", "rl", "--policy", "{tmp}"], {}),
    ("train-episodes-zero", ["train", "--episodes", "0", "--out", "{tmp}/run"], {}),
    ("train-episodes-negative", ["train", "--episodes", "-2", "--out", "{tmp}/run"], {}),
    ("train-seed-negative", ["train", "--seed", "-1", "--out", "{tmp}/run"], {}),
    ("train-unknown-preset", ["train", "--preset", "huge", "--out", "{tmp}/run"], {}),
    ("train-resume-and-force", ["train", "--resume", "--force", "--out", "{tmp}/run"], {}),
    ("train-resume-nothing", ["train", "--resume", "--out", "{tmp}/run"], {}),
    ("train-address-without-seeds", ["train", "--address", "1.2.3.4:1", "--out", "{tmp}/r"], {}),
    ("train-seeds-words", ["train", "--seeds", "a,b", "--out", "{tmp}/run"], {}),
    ("train-seeds-backwards", ["train", "--seeds", "3-1", "--out", "{tmp}/run"], {}),
    ("train-seeds-negative", ["train", "--seeds", "-1", "--out", "{tmp}/run"], {}),
    ("train-seed-and-seeds", ["train", "--seed", "1", "--seeds", "0,1", "--out", "{tmp}/r"], {}),
    ("tune-pd-per-case-zero", ["tune-pd", "--per-case", "0", "--out", "{tmp}/g.toml"], {}),
    ("tune-pd-unknown-object", ["tune-pd", "--objects", "ball", "--out", "{tmp}/g.toml"], {}),
    ("tune-pd-duration-zero", ["tune-pd", "--duration", "0", "--out", "{tmp}/g.toml"], {}),
    ("tune-feedback-plant", ["tune-feedback", "--plant", "real", "--out", "{tmp}/f.toml"], {}),
    ("sweep-missing-config", ["sweep", "{tmp}/none.toml"], {}),
    ("sweep-config-not-toml", ["sweep", "{tmp}/s.toml"], {"s.toml": "this is = = not toml"}),
    ("sweep-config-empty", ["sweep", "{tmp}/s.toml"], {"s.toml": ""}),
    ("info-unknown-object", ["info", "--object", "pyramid"], {}),
    ("info-unknown-arm", ["info", "--arm", "ur10"], {}),
    # ---- training presets
    *[
        (f"preset-{name}", ["train", "--preset", "{tmp}/p.toml", "--out", "{tmp}/run"],
         {"p.toml": text})
        for name, text in [
            ("hidden-1e8", QUICK_PRESET.format(ddpg="hidden = [1e8, 1e8]")),
            ("hidden-wide", QUICK_PRESET.format(ddpg="hidden = [100000, 100000]")),
            ("hidden-deep", QUICK_PRESET.format(ddpg="hidden = [8, 8, 8, 8, 8, 8, 8, 8, 8]")),
            ("hidden-empty", QUICK_PRESET.format(ddpg="hidden = []")),
            ("hidden-zero", QUICK_PRESET.format(ddpg="hidden = [0, 8]")),
            ("hidden-text", QUICK_PRESET.format(ddpg='hidden = "big"')),
            ("batch-zero", QUICK_PRESET.format(ddpg="batch_size = 0")),
            ("unknown-ddpg-key", QUICK_PRESET.format(ddpg="learning = 1")),
            ("unknown-table", "[training]\nepisodes = 3\n"),
            ("episodes-zero", "[train]\nepisodes = 0\n"),
            ("episodes-float", "[train]\nepisodes = 2.5\n"),
            ("workers-many", "[train]\nworkers = 99\n"),
            ("checkpoint-zero", "[train]\ncheckpoint_every = 0\n"),
            ("select-on-bad", '[train]\nselect_on = "luck"\n'),
            ("env-unknown-object", '[env]\nobjects = ["sphere"]\n'),
            ("env-duration-negative", "[env]\nduration = -1.0\n"),
            ("env-dt-nan", "[env]\ndt = nan\n"),
            ("not-toml", "[train\nepisodes = "),
            ("binary", b"\x00\xff\xfe\x89PNG\r\n"),
            ("empty-table-value", "[train]\nepisodes =\n"),
        ]
    ],
    ("preset-missing-file", ["train", "--preset", "{tmp}/none.toml", "--out", "{tmp}/r"], {}),
    # ---- objects
    *[
        (f"object-{name}", ["plan", *GOAL, "--object", "{tmp}/o.toml"], {"o.toml": text})
        for name, text in [
            ("mass-huge", OBJECT.format(mass="1e12", size="0.088")),
            ("mass-tiny", OBJECT.format(mass="1e-9", size="0.088")),
            ("mass-zero", OBJECT.format(mass="0.0", size="0.088")),
            ("mass-negative", OBJECT.format(mass="-1.0", size="0.088")),
            ("mass-text", OBJECT.format(mass='"heavy"', size="0.088")),
            ("mass-inf", OBJECT.format(mass="inf", size="0.088")),
            ("size-negative", OBJECT.format(mass="0.3", size="-0.088")),
            ("size-zero", OBJECT.format(mass="0.3", size="0.0")),
            ("no-mass", "height = 0.088\nsize = [0.088, 0.088]\n"),
            ("unknown-key", OBJECT.format(mass="0.3", size="0.088") + "colour = 'red'\n"),
            ("not-toml", "mass = = 3"),
            ("footprint-two-points", "mass = 0.3\nheight = 0.05\nfootprint = [[0, 0], [1, 0]]\n"),
        ]
    ],
    ("object-missing-file", ["plan", *GOAL, "--object", "{tmp}/none.toml"], {}),
    # ---- pushers
    *[
        (f"pusher-{name}", ["plan", *GOAL, "--pusher", "{tmp}/p.toml"], {"p.toml": text})
        for name, text in [
            ("no-prongs", PUSHER.format(n=0, spacing=0.02, mass=0.03)),
            ("five-prongs", PUSHER.format(n=5, spacing=0.02, mass=0.03)),
            ("spacing-zero", PUSHER.format(n=2, spacing=0.0, mass=0.03)),
            ("spacing-negative", PUSHER.format(n=2, spacing=-0.02, mass=0.03)),
            ("spacing-wider-than-plate", PUSHER.format(n=4, spacing=0.05, mass=0.03)),
            ("spacing-huge", PUSHER.format(n=2, spacing=1e3, mass=0.03)),
            ("mass-huge", PUSHER.format(n=2, spacing=0.07, mass=1e6)),
            ("mass-zero", PUSHER.format(n=2, spacing=0.07, mass=0.0)),
            ("prongs-float", PUSHER.format(n=2.5, spacing=0.07, mass=0.03)),
            ("unknown-key", PUSHER.format(n=2, spacing=0.07, mass=0.03) + "colour = 1\n"),
            ("not-toml", "n_prongs = [2"),
        ]
    ],
    ("pusher-missing-file", ["plan", *GOAL, "--pusher", "{tmp}/none.toml"], {}),
    # ---- gains
    *[
        (f"gains-{name}", [*SIM, "--gains", "{tmp}/g.toml"], {"g.toml": text})
        for name, text in [
            ("kp-1e300", GAINS.format(kp="1e300", kv="300.0")),
            ("kp-negative", GAINS.format(kp="-1.0", kv="300.0")),
            ("kp-nan", GAINS.format(kp="nan", kv="300.0")),
            ("kv-zero", GAINS.format(kp="30.0", kv="0.0")),
            ("kv-huge", GAINS.format(kp="30.0", kv="1e30")),
            ("kp-text", GAINS.format(kp='"stiff"', kv="300.0")),
            ("no-pd-table", "kp = 3\n"),
            ("missing-key", "[pd]\nkp = 30.0\n"),
            ("unknown-key", GAINS.format(kp="30.0", kv="300.0") + "ki = 2.0\n"),
            ("not-toml", "[pd\nkp = "),
        ]
    ],
    ("gains-missing-file", [*SIM, "--gains", "{tmp}/none.toml"], {}),
    # ---- policy files
    *[
        (f"policy-{name}", [*EVAL, "--controller", "rl", "--policy", "{tmp}/p.pt",
                            "--out", "{tmp}/eval"], {"p.pt": make})
        for name, make in [
            ("zero-bytes", b""),
            ("text", "not a policy\n"),
            ("garbage", bytes(range(256)) * 8),
            ("truncated", lambda: SHIPPED_POLICY.read_bytes()[:3000]),
            ("flipped-bytes", lambda: _flipped(SHIPPED_POLICY.read_bytes())),
            ("nan-weights", lambda: _policy_bytes(nan=True)),
            ("edited-weights", lambda: _policy_bytes(scale=1e26)),
            ("a-list", lambda: _torch_bytes([1, 2, 3])),
            ("wrong-format", lambda: _torch_bytes({"format": 99})),
            ("no-actor", lambda: _torch_bytes({"format": 1, "env": {}, "made_by": ""})),
        ]
    ],  # fmt: skip
    # ---- results files
    *[
        (f"results-{name}", ["report", "--in", "{tmp}/results", "--out", "{tmp}/report"],
         {"results": make})
        for name, make in [
            ("trials-cut-short", lambda root: _cut(root / "evaluation" / "trials.csv", 3)),
            ("trials-cut-half", lambda root: _cut(root / "evaluation" / "trials.csv", 40)),
            ("trials-empty", lambda root: (root / "evaluation" / "trials.csv").write_text("")),
            ("trials-garbage", lambda root: (root / "evaluation" / "trials.csv").write_bytes(
                b"\x89PNG\x00\xff")),
            ("trials-missing", lambda root: (root / "evaluation" / "trials.csv").unlink()),
            ("trials-no-column", lambda root: _edit(root / "evaluation" / "trials.csv",
                                                   "force_error", "force_err")),
            ("trials-word", lambda root: _edit(root / "evaluation" / "trials.csv", ",0.001,",
                                               ",lots,")),
            ("steps-missing", lambda root: (root / "evaluation" / "steps.csv").unlink()),
            ("curve-text", lambda root: (root / "training" / "curve.csv").write_text("a\n")),
        ]
    ],  # fmt: skip
    ("results-no-dir", ["report", "--in", "{tmp}/none", "--out", "{tmp}/report"], {}),
    # ---- paths
    ("path-plan-out-suffix", ["plan", *GOAL, "--out", "{tmp}/plan.txt"], {}),
    ("path-plan-out-no-dir", ["plan", *GOAL, "--out", "{tmp}/none/plan.csv"], {}),
    ("path-plan-out-is-dir", ["plan", *GOAL, "--out", "{tmp}/d.csv"], {"d.csv/x": "keep"}),
    ("path-plan-plot-suffix", ["plan", *GOAL, "--plot", "{tmp}/plan.jpg"], {}),
    ("path-plan-out-exists", ["plan", *GOAL, "--out", "{tmp}/old.csv"], {"old.csv": "keep"}),
    ("path-simulate-out-no-dir", [*SIM, "--out", "{tmp}/none/trace.csv"], {}),
    ("path-evaluate-out-file", [*EVAL, "--controller", "pd", "--out", "{tmp}/f"], {"f": "x"}),
    ("path-evaluate-out-occupied", [*EVAL, "--controller", "pd", "--out", "{tmp}/e"],
     {"e/notes.txt": "keep"}),
    ("path-train-out-file", ["train", "--out", "{tmp}/f"], {"f": "x"}),
    ("path-train-out-occupied", ["train", "--out", "{tmp}/r"], {"r/notes.txt": "keep"}),
    ("path-report-out-file", ["report", "--in", "{tmp}/results", "--out", "{tmp}/f"],
     {"f": "x", "results": lambda root: None}),
    ("path-tune-pd-out-exists", ["tune-pd", "--out", "{tmp}/g.toml"], {"g.toml": "keep"}),
]  # fmt: skip


def _flipped(data: bytes) -> bytes:
    damaged = bytearray(data)
    rng = random.Random(7)
    for _ in range(16):
        damaged[rng.randrange(len(data) // 4, len(data) // 2)] ^= 0xFF
    return bytes(damaged)


def _torch_bytes(value: object) -> bytes:
    import io

    buffer = io.BytesIO()
    torch.save(value, buffer)
    return buffer.getvalue()


def _policy_bytes(nan: bool = False, scale: float = 1.0) -> bytes | None:
    """The shipped policy with its first weight NaN (saved with a valid digest) or scaled
    (saved by torch alone, keeping the old digest)."""
    state = torch.load(SHIPPED_POLICY, weights_only=True)
    weights = state["actor"]["actor"]
    first = next(iter(weights))
    if nan:
        weights[first] = weights[first].clone().fill_(math.nan)
        state.pop("digest", None)
        return state  # written by save_checked (a digest of the NaN content)
    weights[first] = weights[first] * scale
    state["digest"] = "0" * 64
    return _torch_bytes(state)


def _cut(path: Path, lines: int) -> None:
    kept = path.read_text().splitlines(keepends=True)
    path.write_text("".join(kept[: len(kept) - lines]))


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def _write_files(tmp: Path, files: dict[str, object]) -> None:
    for name, content in files.items():
        path = tmp / name
        if name == "results":
            write_results(path)
            content(path)
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        value = content() if callable(content) else content
        if isinstance(value, dict):
            save_checked(path, value)
        elif isinstance(value, bytes):
            path.write_bytes(value)
        else:
            path.write_text(value)


def _tree(root: Path) -> dict[str, bytes | None]:
    return {
        str(p.relative_to(root)): p.read_bytes() if p.is_file() else None
        for p in sorted(root.rglob("*"))
    }


def test_the_table_has_a_hundred_cases() -> None:
    assert len(CASES) >= 100
    assert len({case[0] for case in CASES}) == len(CASES)


@pytest.mark.parametrize(("args", "files"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_is_one_error_line_and_writes_nothing(
    args: list[str], files: dict[str, object], tmp_path: Path, monkeypatch
) -> None:
    work = tmp_path / "work"
    work.mkdir()
    _write_files(work, files)
    monkeypatch.chdir(work)  # a default output (runs/…, results/…) would land here
    before = _tree(work)
    result = runner.invoke(app, [arg.replace("{tmp}", str(work)) for arg in args])
    assert result.exit_code == 2, (result.exit_code, result.output, result.exception)
    assert "Traceback" not in result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert _tree(work) == before  # no partial output


FEEDBACK = "[feedback]\nk = {k}\nk_i = 0.1\ncontact_force = 0.05\n"
FEEDBACK_CASES = {
    "k-1e200": FEEDBACK.format(k="1e200"),
    "k-negative": FEEDBACK.format(k="-1.0"),
    "k-text": FEEDBACK.format(k='"fast"'),
    "k-nan": FEEDBACK.format(k="nan"),
    "no-table": "k = 1.0\n",
    "unknown-key": FEEDBACK.format(k="1.0") + "kd = 3.0\n",
    "not-toml": "[feedback\nk = ",
}


@pytest.mark.parametrize("text", FEEDBACK_CASES.values(), ids=FEEDBACK_CASES.keys())
def test_a_bad_feedback_gains_file_is_one_line_naming_it(text, tmp_path, monkeypatch) -> None:
    path = tmp_path / "feedback_gains.toml"
    path.write_text(text)
    monkeypatch.setattr("pushctl.control.feedback_gains.DEFAULT_FEEDBACK_FILE", path)
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, [*SIM, "--controller", "feedback"])
    assert result.exit_code == 2, (result.output, result.exception)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert str(path) in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["feedback_gains.toml"]
