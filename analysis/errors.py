"""The error an analysis user can cause. The command line prints its message and exits with status 2."""


class AnalysisError(Exception):
    """A problem with the video or the options given; the message says what was wrong and what to do."""
