"""Simulation: textured worlds, cameras, LiDAR, motion and recorded runs (filled in below)."""
