"""Evaluation: the PD gain search (``pushctl tune-pd``), the PD sweep, and the paired PD-only
vs RL-assisted trials of ``pushctl evaluate`` (:mod:`~pushctl.evaluation.trials`,
:mod:`~pushctl.evaluation.evaluate`)."""
