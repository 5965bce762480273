"""Studies: the measurements behind the defaults and the docs' tables, run from the checkout
(not installed). Each module is run as ``python -m studies.<name>`` from the repository's
root (``make studies`` lists them); none is imported by ``pushctl``.

- :mod:`studies.failure_study`, :mod:`studies.landing_study`, :mod:`studies.residual_study`:
  the feedback law's and the residual's settings on the tuning stream;
- :mod:`studies.pd_sweep`: the PD baseline on many drawn scenarios
  (``results/pd_sweep_*.csv``);
- :mod:`studies.mujoco_validation`, :mod:`studies.mujoco_transfer`: our engine against MuJoCo
  (tables into ``runs/``, or a docs page's table with ``--docs``);
- :mod:`studies.acceptance`: paired RL − PD-only differences per cell from a ``trials.csv``;
- :mod:`studies.readme_table`: the README's results table from a results directory.
"""
