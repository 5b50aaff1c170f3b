"""The error a predictor user can cause (bad input, asking before any sample arrived)."""


class PredictorError(ValueError):
    """Invalid input to a predictor or pose type; the message says what was wrong."""
