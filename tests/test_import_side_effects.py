"""``import pushctl`` changes nothing outside the package: no environment variable is set and
no file is deleted (not even a stale kernel cache: the ``pushctl`` command and the test
suite drop those explicitly, :func:`pushctl.machine.kernel_cache.drop_stale`)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pushctl
from pushctl.machine.kernel_cache import drop_stale

PROBE = """
import json, os, sys
before = dict(os.environ)
import pushctl
print(json.dumps({"environ_unchanged": dict(os.environ) == before,
                  "numpy_loaded": "numpy" in sys.modules,
                  "pushctl": pushctl.__file__}))
"""


def test_importing_pushctl_sets_nothing_and_deletes_nothing(tmp_path: Path) -> None:
    copy = tmp_path / "pushctl"
    shutil.copytree(Path(pushctl.__file__).parent, copy, ignore=shutil.ignore_patterns("lib"))
    # a kernel cache whose recorded dependencies no longer match: drop_stale would remove it
    cache = copy / "contact" / "compiled" / "__pycache__"
    cache.mkdir(exist_ok=True)
    (cache / "step.deps").write_text("stale")
    decoy = cache / "step.slip_step-1.py311.nbi"
    decoy.write_bytes(b"cached")
    files = {path for path in copy.rglob("*") if path.is_file()}
    done = subprocess.run(
        [sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=300,
        cwd=tmp_path, env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(tmp_path)},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert report["pushctl"].startswith(str(copy))
    assert report["environ_unchanged"]
    assert not report["numpy_loaded"]  # so pushctl.reproducible() can still pin its code
    assert files <= {path for path in copy.rglob("*") if path.is_file()}
    # what would have deleted the decoy is an explicit call
    assert copy / "contact" / "compiled" / "step.py" in drop_stale(copy)
    assert not decoy.exists()


def test_importing_the_command_line_sets_nothing() -> None:
    """``import pushctl.cli`` is as inert as ``import pushctl``: the pinning and the cache
    sweep belong to the ``pushctl`` command (:func:`pushctl.cli.main`)."""
    code = (
        "import json, os, sys; before = dict(os.environ); import pushctl.cli; "
        "print(json.dumps([dict(os.environ) == before, 'numpy' in sys.modules]))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == [True, False]
