"""The README's Python example runs as written."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert blocks, "the README has no Python example"
    namespace: dict = {}
    exec(compile(blocks[0], str(README), "exec"), namespace)  # noqa: S102 - our own README
    assert namespace["sol"].converged
    assert abs(namespace["table"].object_pose[0] - 0.5**2 / (2 * 0.3 * 9.81)) < 1e-3


def test_readme_planning_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    planning = [block for block in blocks if "make_plan" in block]
    assert planning, "the README has no planning example"
    namespace: dict = {}
    exec(compile(planning[0], str(README), "exec"), namespace)  # noqa: S102 - our own README
    plan = namespace["plan"]
    assert plan.feasible and plan.problems == ()
    assert plan.forces.forces.shape == (2001, 2, 2)


def test_readme_episode_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    episodes = [block for block in blocks if "Episode(" in block]
    assert episodes, "the README has no episode example"
    namespace: dict = {}
    exec(compile(episodes[0], str(README), "exec"), namespace)  # noqa: S102 - our own README
    metrics = namespace["metrics"]
    assert namespace["trace"].n_steps == 2000
    assert metrics.translation_error_pct < 1.0 and metrics.max_penetration < 1e-3
