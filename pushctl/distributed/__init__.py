"""Parallel work on Ray: the only package that imports ``ray``.

- :mod:`pushctl.distributed.engine`: joining or starting Ray, and pools of worker processes
  (evaluation trials, training collectors) that give results in submission order.
- :mod:`pushctl.distributed.seeds`: one training run per seed, as Ray tasks, each in its own
  ``RUN/seed-K/``, retried from its last checkpoint when its worker dies.
- :mod:`pushctl.distributed.sweep`: grid or random search over preset keys × seeds, scored
  on the validation set (tuning stream).

Without an address Ray starts on this machine (its cores, no dashboard, quiet logs); with
``--address`` or ``RAY_ADDRESS`` it joins a running cluster (docs/ray.md).
"""
