"""The lines the commands print about a measurement (shared by `rig analyse` and `rig demo`)."""

from __future__ import annotations

from analysis import LatencyResult
from analysis.board.reference import EVENT_NAME, BoardReference


def warning_text(warning: str, title: str = "warning") -> str:
    """A warning as printed: its first line (the cause) after the title, the next (the remedy,
    `analysis.caveat`) indented under it."""
    return f"{title}: " + warning.replace("\n", "\n  ")


def summary_line(result: LatencyResult) -> str:
    """The one line a lab reads."""
    ci = f" (95% CI {result.ci95_ms[0]:.2f} to {result.ci95_ms[1]:.2f} ms)" if result.ci95_ms else ""
    flag = " AMBIGUOUS" if result.ambiguous else ""
    spread = (
        f", per swing sd {result.windowed.sd_s * 1e3:.2f} ms" if result.windowed is not None and result.windowed.count > 1 else ""
    )
    return (
        f"latency {result.latency_ms:.2f} ms{ci}{flag} by {result.method} ({result.model}), "
        f"swing period {result.period_s:.4f} s{spread}, {result.frames_used}/{result.frames} frames used"
    )


def board_line(board: BoardReference, result: LatencyResult) -> str:
    """What the board recording told: the clock offset, and the start of swing it saw."""
    alignment = board.alignment
    assert alignment is not None
    line = (
        f"board: video on the board's clock by the blink code (offset {alignment.offset_s:.4f} s, "
        f"within {(alignment.high_s - alignment.low_s) * 1e3:.1f} ms, {alignment.agreement:.0%} of frames agree)"
    )
    lag = result.cycles.events_s.get(EVENT_NAME)
    if board.departure_board_s is None:
        return line + "; the encoder did not start from rest while filmed, so it fixed nothing"
    if lag is None:
        return line + "; the sphere's start of swing is not in the video, so the encoder's fixed nothing"
    return line + f"; the sphere left rest {lag * 1e3:.0f} ms after the encoder did"


def hints_line(result: LatencyResult) -> str | None:
    """What the analysis made of each value the bench profile gave (None without a profile)."""
    if not result.hints:
        return None
    verdicts = [
        f"{check.hint.name} {check.verdict}" + (f" ({check.used})" if check.verdict == "overruled" else "") for check in result.hints
    ]
    return "bench profile against the video: " + ", ".join(verdicts)
