"""Figures for talks and papers: ``plan_figure`` draws a push plan (the arc, the object along
it, the prongs and plate, and the planned rotation, prong forces and torques over time)."""

from pushctl.report.plan_figure import plan_figure

__all__ = ["plan_figure"]
