"""Simulated robot parts, each a real ROS 2 node; `python -m rover_web.sim` runs them all."""
