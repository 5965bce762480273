"""This tree against another commit, side by side (``python -m benchmarks.compare_commits``):
the reference's ``pushctl/`` and ``experiments/`` unpacked with ``git archive``, each run a
fresh process, the trees alternating which goes first.

- :mod:`benchmarks.commits.step`: the world step, cold MLCP solves and env steps;
- :mod:`benchmarks.commits.evaluate`: a short ``pushctl evaluate``, outputs compared byte
  for byte;
- :mod:`benchmarks.commits.train`: a short ``pushctl train``, likewise;
- :mod:`benchmarks.commits.trees`: what the last two share.
"""
