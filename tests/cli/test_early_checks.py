"""A typo is refused before the core is imported: ``evaluate`` and ``train`` check their
options first (:mod:`pushctl.cli.names`), so a bad name costs no time."""

from __future__ import annotations

import subprocess
import sys

import pytest

from pushctl.cli import names

HEAVY = ("torch", "pushctl.evaluation.trials", "pushctl.rl.train", "pushctl.contact.world")


@pytest.mark.parametrize(
    "args",
    [
        ["evaluate", "--profile", "sine"],
        ["evaluate", "--object", "ball"],
        ["evaluate", "--controller", "lqr"],
        ["evaluate", "--plant", "robot"],
        ["evaluate", "--stream", "test"],
        ["evaluate", "--trials", "0"],
        ["train", "--preset", "huge"],
        ["train", "--preset", "missing.toml"],
        ["train", "--resume", "--force"],
        ["train", "--seed", "-1"],
    ],
    ids=lambda args: " ".join(args),
)
def test_a_typo_is_refused_before_the_core_is_imported(args):
    script = (
        "import sys\n"
        "from pushctl.cli import app\n"
        "try:\n"
        f"    app({args!r})\n"
        "except SystemExit as end:\n"
        "    print(end.code, *[m for m in " + repr(HEAVY) + " if m in sys.modules])\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=120)  # fmt: skip
    assert done.stdout.split() == ["2"], (done.stdout, done.stderr)
    assert done.stderr.startswith("error: "), done.stderr


def test_the_early_names_are_the_cores():
    from pushctl.config import PLANT_KINDS
    from pushctl.evaluation.trials import SEEDS_PER_EVALUATION, STREAMS_EVALUATED
    from pushctl.objects import OBJECT_NAMES
    from pushctl.planning import PROFILE_NAMES
    from pushctl.rl.presets import PRESET_NAMES

    assert names.OBJECTS == OBJECT_NAMES and names.PROFILES == PROFILE_NAMES
    assert names.PLANTS == PLANT_KINDS
    assert names.STREAMS == STREAMS_EVALUATED and names.PRESETS == PRESET_NAMES
    assert names.MAX_TRIALS == SEEDS_PER_EVALUATION
