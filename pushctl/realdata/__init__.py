"""Recorded robot pushes replayed in the kinematic world and scored (docs/realdata.md)."""
