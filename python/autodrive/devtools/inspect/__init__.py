"""Inspection of runs in the tools robotics people use: MCAP export for Foxglove and ros2 bag."""
