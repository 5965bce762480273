"""Contact dynamics: the box-friction MLCP solver and the world step."""

from pushctl.contact.mlcp import MLCPResult, solve_box_mlcp

__all__ = ["MLCPResult", "solve_box_mlcp"]
