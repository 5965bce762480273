"""Figures for talks and papers: ``plan_figure`` draws a push plan (the arc, the object along
it, the prongs and plate, and the planned rotation, prong forces and torques over time);
``trace_figure`` draws a simulated push (desired against actual path, rotation, tracking
error, prong forces and torque over time)."""

from pushctl.report.plan_figure import plan_figure
from pushctl.report.trace_figure import trace_figure

__all__ = ["plan_figure", "trace_figure"]
