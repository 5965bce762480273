"""Benchmarks: timings of the simulator core and the learning side, run from the checkout
(not installed; nothing in ``pushctl`` imports them).

- ``make bench`` (``python -m benchmarks.suite``): every row, as a table, a CSV
  (``results/bench.csv``) and the table of ``docs/performance.md``; its rows come from
  :mod:`benchmarks.engines` (our world and MuJoCo side by side: one core, interleaved,
  medians), :mod:`benchmarks.episode` (closed loop) and :mod:`benchmarks.rl` (learning);
- ``python -m benchmarks.compare_commits {step,evaluate,train} --against REV``: this tree
  against another commit, side by side (opt-in; needs that commit in the git history);
- :mod:`benchmarks.profile_env`, :mod:`benchmarks.slip_loop`,
  :mod:`benchmarks.worker_priority`: focused measurements, each run alone.
"""
