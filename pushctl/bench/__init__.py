"""Benchmarks (``make bench``): timings of the simulator core and the learning side.

- ``python -m pushctl.bench`` (:mod:`pushctl.bench.suite`): every row, as a table and CSV;
  its rows come from :mod:`pushctl.bench.episode` (closed loop), :mod:`pushctl.bench.rl`
  (learning) and :mod:`pushctl.bench.engines` (our world and MuJoCo side by side);
- ``python -m pushctl.bench.compare``: this tree against a reference commit, side by side.
- ``python -m pushctl.bench.evaluation``: a short ``pushctl evaluate`` of this tree against a
  reference commit, side by side, the outputs compared byte for byte.

Nothing in the core imports this package.
"""
