"""Digests that pin what ``results/`` ships: every shipped file's sha256, and the digests of
two small pieces recomputed from the code (a short evaluation of the shipped seed-0 policy,
a few training episodes of the ``paper`` preset), recorded in ``tests/data/shipped_digests.json``.

A recomputed digest repeats only on a machine of the kind it was recorded on, so each is
recorded with its scope: the fields of :data:`pushctl.machine.SCOPES` for its kind of run
(CPU, the code numpy, torch and MKL chose, library versions). The manifest may hold one
record per scope; a test checks the record of this machine's scope and skips, naming what
differs, where there is none.

A change that is meant to move results (then ``make reproduce-tables`` makes ``results/``
again) re-records them: ``python tests/shipped_digests.py --record`` (``make digests``)
keeps this machine's records only. ``--add`` adds this machine's records to the others, for
a code that has not changed, run on a machine of another kind.
"""

from __future__ import annotations

import hashlib
import json
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "results"
MANIFEST = ROOT / "tests" / "data" / "shipped_digests.json"
UNPINNED = ("bench.csv", "provenance.md")
"""Shipped files that are not results of a seed: the bench's timings and the manifest of
the run that made ``results/`` (its dates and wall times)."""
KEPT_COMPRESSED = ("evaluation/steps.csv",)
"""Files ``make reproduce-tables`` writes that the repository ships only compressed
(``.gitignore`` keeps them out; a clean clone has only the ``.gz``)."""

EVALUATION_ARGS = ["evaluate", "--object", "cube", "--profile", "constant", "--trials", "2",
                   "--controller", "all", "--plant", "all", "--seed", "0",
                   "--stream", "evaluation"]  # fmt: skip
"""The short evaluation (with ``--policy`` the shipped seed-0 policy and ``--out``)."""
TRAINING = {"episodes": 4, "episodes_per_round": 2, "workers": 0, "checkpoint_every": 2,
            "validate_every": 2, "validation_per_cell": 1}  # fmt: skip
TRAINING_DDPG = {"warmup_steps": 80, "critic_burn_in": 20}
"""The ``paper`` preset's [train] and [ddpg] keys replaced for the short training run (its
seed: 3): two rounds of two episodes in this process, updates after a short warm-up."""


def file_digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def shipped_files() -> dict[str, str]:
    """Path under ``results/`` → sha256 of every shipped file but :data:`UNPINNED` (and
    :data:`KEPT_COMPRESSED`, which a clean clone does not have)."""
    files = (path for path in sorted(RESULTS.rglob("*")) if path.is_file())
    names = {path.relative_to(RESULTS).as_posix(): path for path in files}
    return {
        name: file_digest(path)
        for name, path in names.items()
        if path.name not in UNPINNED and name not in KEPT_COMPRESSED
    }


def content_digest(*paths: Path) -> str:
    """sha256 of the files' text without their comment lines (``# made by: …`` names the
    command, the commit and the date)."""
    digest = hashlib.sha256()
    for path in paths:
        lines = path.read_text().splitlines(keepends=True)
        digest.update("".join(line for line in lines if not line.startswith("#")).encode())
    return digest.hexdigest()


def evaluation_digest(out: Path) -> str:
    """Run the short evaluation into ``out``; the digest of its trials and steps."""
    from typer.testing import CliRunner

    from pushctl.cli import app

    policy = RESULTS / "training" / "seed-0" / "policy.pt"
    args = [*EVALUATION_ARGS, "--policy", str(policy), "--out", str(out)]
    done = CliRunner().invoke(app, args)
    if done.exit_code != 0:
        raise RuntimeError(done.output)
    return content_digest(out / "trials.csv", out / "steps.csv")


def training_digest(out: Path) -> str:
    """Train the short run into ``out``; the digest of its curves and its actor's weights."""
    from pushctl.rl.presets import load_preset
    from pushctl.rl.train import Trainer

    paper = load_preset("paper")
    preset = replace(
        paper,
        train=replace(paper.train, **TRAINING),
        ddpg=replace(paper.ddpg, **TRAINING_DDPG),
    )
    trainer = Trainer.start(preset, 3, out)
    trainer.run(TRAINING["episodes"])
    digest = hashlib.sha256(content_digest(out / "curve.csv", out / "validation.csv").encode())
    for name, tensor in sorted(trainer.agent.actor.state_dict().items()):
        digest.update(name.encode())
        digest.update(tensor.detach().cpu().contiguous().numpy().tobytes())
    return digest.hexdigest()


DIGESTS = {"evaluation": evaluation_digest, "training": training_digest}
"""Each recomputed digest by its kind of run (a key of :data:`pushctl.machine.SCOPES`)."""


def recorded_for_this_machine(kind: str) -> tuple[str | None, str]:
    """The digest of ``kind`` recorded for this machine's scope, and ``""``; or ``None`` and
    why none applies (each recorded scope's first differences from this machine's)."""
    from pushctl.machine import reproducibility_scope, scope_differences, scope_of

    here = scope_of(kind, reproducibility_scope())
    records = json.loads(MANIFEST.read_text()).get(kind, [])
    for entry in records:
        if entry["scope"] == here:
            return entry["digest"], ""
    others = ["; ".join(scope_differences(entry["scope"], here)) for entry in records]
    return None, f"the {kind} digest was recorded on other machines only ({' | '.join(others)})"


def record(scratch: Path, add: bool) -> dict[str, object]:
    """Recompute the digests on this machine and write the manifest: with ``add``, beside
    the records of other scopes (the shipped files' digests must be unchanged); without,
    replacing every record."""
    from pushctl.machine import reproducibility_scope, scope_of

    scope = reproducibility_scope()
    old = json.loads(MANIFEST.read_text()) if add and MANIFEST.exists() else {}
    manifest: dict[str, object] = {"results": shipped_files()}
    if add and old.get("results") != manifest["results"]:
        raise SystemExit("--add: the shipped files changed; record them anew with --record")
    for kind, digest in DIGESTS.items():
        mine = scope_of(kind, scope)
        kept = [entry for entry in old.get(kind, []) if entry["scope"] != mine]
        manifest[kind] = [*kept, {"scope": mine, "digest": digest(scratch / kind)}]
    MANIFEST.parent.mkdir(parents=True, exist_ok=True)
    MANIFEST.write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    return manifest


if __name__ == "__main__":
    import tempfile

    import pushctl

    pushctl.reproducible()  # the CPU code the tests run (tests/conftest.py)
    if sys.argv[1:] not in (["--record"], ["--add"]):
        sys.exit("usage: python tests/shipped_digests.py --record | --add")
    with tempfile.TemporaryDirectory() as scratch:
        print(json.dumps(record(Path(scratch), add=sys.argv[1] == "--add"), indent=1))
