"""Residual reinforcement learning: the gymnasium environment, DDPG, and the training loop."""
