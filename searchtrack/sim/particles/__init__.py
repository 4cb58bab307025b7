"""Particles in open space: the standard SMC-PHD scenario and the offline filter of recorded 2-D
detections, paper 003's closed-loop multi-UAV tracking and paper 004's 3-D search episodes."""
