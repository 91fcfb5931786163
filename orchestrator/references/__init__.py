"""Monolithic references: the physics of a scene assembled into one ODE with exact events."""
