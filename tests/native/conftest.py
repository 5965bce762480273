"""The compiled library's tests skip where it is not built (a plain `pip install -e .`),
and fail there instead when PUSHCTL_EXPECT_NATIVE=1 (CI, .ci/run): a build that silently
failed would otherwise leave them skipped."""

import os

import pytest

from pushctl import native


def pytest_collection_modifyitems(config, items):
    if native.available():
        return
    here = os.path.dirname(__file__)
    ours = [item for item in items if str(item.fspath).startswith(here)]
    if os.environ.get("PUSHCTL_EXPECT_NATIVE") == "1":
        raise pytest.UsageError(
            f"pushctl's compiled library is not in use ({native.status()}): "
            'python -c "from pushctl.native.build import build; print(build())"'
        )
    for item in ours:
        item.add_marker(pytest.mark.skip(reason=f"not in use: {native.status()}"))
