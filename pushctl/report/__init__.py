"""Figures for talks and papers: ``plan_figure`` draws a push plan (the arc, the object along
it, the prongs and plate, and the planned rotation, prong forces and torques over time);
``trace_figure`` draws a simulated push (desired against actual path, rotation, tracking
error, prong forces and torque over time).

The evaluation report (``pushctl report``): ``read_report_inputs`` reads and checks the
results CSVs, ``table3``/``table4`` compute the paper's Tables III and IV (means and 95 %
confidence intervals), ``tables_markdown`` sets them beside the paper's values, and
``training_figure``, ``tracking_figure`` and ``force_error_figure`` draw Figs. 5, 6 and 8.
"""

from pushctl.report.figures import force_error_figure, tracking_figure, training_figure
from pushctl.report.inputs import ReportInputs, ResultsFileError, read_report_inputs
from pushctl.report.markdown import tables_markdown
from pushctl.report.plan_figure import plan_figure
from pushctl.report.tables import ResultTable, ci95_halfwidth, table3, table4
from pushctl.report.trace_figure import trace_figure

__all__ = [
    "ReportInputs",
    "ResultTable",
    "ResultsFileError",
    "ci95_halfwidth",
    "force_error_figure",
    "plan_figure",
    "read_report_inputs",
    "table3",
    "table4",
    "tables_markdown",
    "trace_figure",
    "tracking_figure",
    "training_figure",
]
