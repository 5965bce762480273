"""Several training runs: one per seed (:mod:`pushctl.runs.seeds`), each in its own
``RUN/seed-K/`` and retried from its last checkpoint when its worker dies, and grid or
random searches over preset keys × seeds scored on the validation set
(:mod:`pushctl.runs.sweep`, :mod:`pushctl.runs.sweep_config`). Their tasks run on Ray
through :mod:`pushctl.distributed`."""
