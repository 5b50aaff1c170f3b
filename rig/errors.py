"""The error a rig user can cause. The command line prints its message and exits with status 2."""


class RigError(Exception):
    """A problem with the user's input or setup; the message says what was wrong and what to do."""


class ConfigError(RigError, ValueError):
    """An option or configuration value outside its allowed range."""


def user_errors() -> tuple[type[Exception], ...]:
    """The error types a user can cause: the rig's and its two libraries' (imported when asked, so
    that the command line starts light)."""
    from analysis.errors import AnalysisError
    from predictors import PredictorError

    return (RigError, PredictorError, AnalysisError)
