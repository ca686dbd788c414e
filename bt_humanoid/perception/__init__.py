"""Perception: what the robot believes about the world (WorldModel), and how that belief is filled."""
