"""Benchmarks behind `rig bench`: speed against error, one module per subject."""
