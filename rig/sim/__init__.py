"""Simulated twins of the rig's devices, deterministic for a seed and run on a virtual clock.

`SimulatedWorld` (rig.sim.world) holds a simulated run's pendulum and bench and makes the twins
of the tracker, display, camera and board that live in it.
"""
