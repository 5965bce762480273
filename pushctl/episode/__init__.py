"""Episodes: a scenario planned, approached, pushed and traced; its metrics."""

from pushctl.episode.runner import ApproachSettings, Episode
from pushctl.episode.scenario import PhysicalParameters, Scenario, stream_rng
from pushctl.episode.trace import Trace

__all__ = ["ApproachSettings", "Episode", "PhysicalParameters", "Scenario", "Trace", "stream_rng"]
