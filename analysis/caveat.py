"""A warning as a lab reads it: one line saying what happened to the number and why, and one line
saying what to do about it; the figures behind it are in the result's JSON (`LatencyResult.to_dict`).

Every warning the analysis gives is made by `caveat`, so that each is two lines, whatever filled it.
"""

from __future__ import annotations

REMEDY = "to avoid it: "
"""How a warning's second line starts."""


def caveat(cause: str, remedy: str) -> str:
    """The warning of `cause` (what happened, one line) and `remedy` (what to do, one line)."""
    for part in (cause, remedy):
        if not part.strip() or "\n" in part:
            raise ValueError(f"a warning's cause and remedy are one line each, got {part!r}")
    return f"{cause}\n{REMEDY}{remedy}"
