"""Parallel work on Ray: the only package that imports ``ray``, and it imports nothing of
pushctl's above the shared basics, so every layer may use it.

- :mod:`pushctl.distributed.engine`: joining or starting Ray, pools of worker processes
  (evaluation trials, training collectors) that give results in submission order, and
  long tasks retried when their worker dies (training seeds: :mod:`pushctl.runs`).
- :mod:`pushctl.distributed.reaper`: a local Ray instance never outlives the command that
  started it.

Without an address Ray starts on this machine (its cores, no dashboard, quiet logs); with
``--address`` or ``RAY_ADDRESS`` it joins a running cluster (docs/ray.md).
"""
