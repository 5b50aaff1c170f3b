"""What a lab says of its bench, offered to the analysis as hints and checked against the video.

A lab describes its camera, display and layout once (the rig's bench profile); each value reaches
the analysis as a `Hint` (its name, value and where it came from) in `AnalysisOptions.hints`. A
hint fills the option of its name where the options leave it unset (an option given wins: the
hint is recorded as overruled), and the analysis compares each hint it can with what the video
shows (`analysis.hints.review`): a contradiction is a warning naming both values, and the hint is
then not used as it stands (the video's value replaces it, or the analysis does without it, as
each check says). Every hint's verdict is in the result (`HintCheck`).

This module stays light (the hint's type and its words): `analysis.options` imports it.
"""

from analysis.hints.hint import APPLIED, CHECKED, SCANOUTS, Hint, HintCheck

__all__ = ["APPLIED", "CHECKED", "SCANOUTS", "Hint", "HintCheck"]
