"""The latencies an analysis considers unless told otherwise: a module of its own, as both the
options (`analysis.options`) and the choice of the whole number of periods (`analysis.cycles`) read it."""

DEFAULT_LATENCY_RANGE_S = (-0.2, 0.6)
"""The latencies considered unless asked otherwise (s): from a prediction 200 ms ahead of the motion to
600 ms behind it."""
