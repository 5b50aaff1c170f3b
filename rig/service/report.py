"""A report a lab can keep: one measurement (a video, or a run folder) or a summary of many, as a
self-contained HTML page and the same content as Markdown (`rig.report.document`).

A run's report analyses its video again (with the run's board recording when the folder has one)
and shows the latency in large type, the tracks over the whole film with the delayed LED laid on
the sphere, the latency swing by swing, the residual, every method, every diagnostic with its
verdict, the warnings, the configuration, the devices, the software versions and the project's
commit. A simulated run's truth is shown beside the measurement. A summary's report (a CSV or JSON
from `rig analyse --summary` or `rig sweep`) compares the runs.
"""

from __future__ import annotations

import csv
import json
import platform
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any, Callable, Sequence

from analysis import LatencyResult
from analysis.board.recording import METADATA
from rig.errors import ConfigError
from rig.report.document import Report, Section, write_html, write_markdown
from rig.report.figures import latency_over_time_figure, residuals_figure, summary_figure, tracks_figure
from rig.service.analyse import AnalysisRequest, Measurement, analyse
from rig.service.batch import RESULT_COLUMNS
from rig.service.compare import Z95, differences, group_latencies
from rig.session.run_files import BOARD_FOLDER
from rig.toml_file import dotted

PACKAGES = ("latency-rig", "numpy", "scipy", "opencv-contrib-python-headless", "jax", "jaxopt", "emcee", "matplotlib", "moderngl")
RUN_VIDEO = "video.avi"
TRUTH = "truth.json"
# Diagnostics a good film passes, and the test each must pass.
DIAGNOSTIC_CHECKS = {
    "dropped_frames": lambda value: value == 0,
    "repeated_frames": lambda value: value == 0,
    "variable_frame_rate": lambda value: not value,
    "detection_rate.led": lambda value: value >= 0.95,
    "detection_rate.sphere": lambda value: value >= 0.95,
    "clipped_frames.led": lambda value: value == 0,
    "clipped_frames.sphere": lambda value: value == 0,
}


def software() -> list[tuple[str, str]]:
    """Python, the packages a measurement depends on, and the project's commit where it is a checkout."""
    rows = [("python", platform.python_version())]
    for name in PACKAGES:
        try:
            rows.append((name, metadata.version(name)))
        except metadata.PackageNotFoundError:
            rows.append((name, "not installed"))
    here = Path(__file__).resolve().parent
    try:
        commit = subprocess.run(["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=5)
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True, timeout=5)
        state = commit.stdout.strip() + (" (with uncommitted changes)" if dirty.stdout.strip() else "") if commit.returncode == 0 else "not a git checkout"
    except (OSError, subprocess.TimeoutExpired):
        state = "git not available"
    return rows + [("project commit", state)]


def _verdict(name: str, value: Any) -> str:
    check = DIAGNOSTIC_CHECKS.get(name)
    if check is None or value is None:
        return "-"
    return "ok" if check(value) else "check"


def _headline(result: LatencyResult) -> str:
    interval = f" (95 % interval {result.ci95_ms[0]:.2f} to {result.ci95_ms[1]:.2f} ms)" if result.ci95_ms else ""
    return f"{result.latency_ms:.2f} ms{interval}"


def _run_verdict(result: LatencyResult, truth: dict[str, Any] | None) -> str:
    if result.ambiguous:
        verdict = "AMBIGUOUS: the whole number of swing periods is not decided; see the warnings"
    elif result.warnings:
        verdict = f"measured, but read the {len(result.warnings)} warning(s)"
    else:
        verdict = "clean: every check passed"
    if truth is not None:
        verdict += f"; simulated truth {truth['latency_ms']:.2f} ms, error {result.latency_ms - truth['latency_ms']:+.3f} ms"
    return verdict


def read_truth(path: Path) -> dict[str, Any]:
    """A simulated run's truth.json (`rig simulate` writes it): an object with its latency_ms (a
    number) and its config (an object); ConfigError naming the file for anything else, before any
    work is done."""
    try:
        truth = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise ConfigError(f"cannot read the simulation's truth {path}: {error}; simulate the run again, or move the file away") from None
    latency = truth.get("latency_ms") if isinstance(truth, dict) else None
    if not (isinstance(latency, (int, float)) and not isinstance(latency, bool) and isinstance(truth.get("config"), dict)):
        raise ConfigError(
            f"{path} is not a simulation's truth: it must be an object with latency_ms (a number) and config (an object), "
            "as rig simulate writes it; simulate the run again, or move the file away"
        )
    return truth


def run_report(path: Path, progress: Callable[[int, int], object] | None = None) -> tuple[Report, Measurement]:
    """The report of a video, or of a run folder holding video.avi (and maybe truth.json, board/);
    `progress(done, total)` as its frames are tracked."""
    path = Path(path)
    folder = path if path.is_dir() and (path / RUN_VIDEO).exists() else None
    video = folder / RUN_VIDEO if folder is not None else path
    truth_path = (folder or video.parent) / TRUTH
    truth = read_truth(truth_path) if truth_path.exists() else None
    board = (folder or video.parent) / BOARD_FOLDER
    request = AnalysisRequest(video, board=board if (board / METADATA).exists() else None)
    measurement = analyse(request, progress)
    result = measurement.result
    report = Report(f"Latency of {video}", _headline(result), _run_verdict(result, truth))
    report.sections.append(Section("Warnings", list(result.warnings) or ["none"]))
    report.sections.append(Section("The film", [("tracks", tracks_figure(result)), ("latency_over_time", latency_over_time_figure(result)),
                                                ("residual", residuals_figure(result))]))  # fmt: skip
    methods = [(name, m.latency_ms, *(m.ci95_ms or (None, None)), m.model) for name, m in result.methods.items()]
    report.sections.append(Section("Methods", [(("method", "latency (ms)", "95 % low", "95 % high", "model"), methods)]))
    diagnostics = [(name, value, _verdict(name, value)) for name, value in dotted(result.diagnostics).items()]
    rows = [("period (s)", result.period_s, "-"), ("frames used", f"{result.frames_used}/{result.frames}", "-"),
            ("ROIs", f"LED {result.led_roi.as_list()}, sphere {result.sphere_roi.as_list()} ({result.roi_source})", "-"),
            ("LED told apart by", result.led_rule, "-"), *diagnostics]  # fmt: skip
    report.sections.append(Section("Diagnostics", [(("diagnostic", "value", "verdict"), rows)]))
    if measurement.board is not None:
        board_rows = list(dotted(measurement.board.to_dict()).items())
        report.sections.append(Section("Board", [(("field", "value"), board_rows)]))
    configuration = [("video", str(video)), ("method", request.options.method), ("latency range (ms)", request.options.latency_range_ms)]
    if truth is not None:
        configuration += [(f"simulation.{k}", v) for k, v in dotted(truth["config"]).items()]
    report.sections.append(Section("Configuration and devices", [(("setting", "value"), configuration)]))
    report.sections.append(Section("Software", [(("software", "version"), software())]))
    return report, measurement


def read_summary(path: Path) -> list[dict[str, Any]]:
    """The rows of a summary CSV or JSON (`rig analyse --summary`, `rig sweep`)."""
    path = Path(path)
    try:
        if path.suffix.lower() == ".json":
            document = json.loads(path.read_text(encoding="utf-8"))
            rows = document.get("rows") if isinstance(document, dict) else None
            if not isinstance(rows, list):
                raise ValueError('a summary JSON is an object whose "rows" is a list, as `rig analyse --summary` and `rig sweep` write')
        else:
            with open(path, newline="", encoding="utf-8") as stream:
                rows = list(csv.DictReader(stream))
        if not all(isinstance(row, dict) and "video" in row for row in rows):
            raise ValueError("every row needs a video column, as `rig analyse --summary` and `rig sweep` write")
        numeric = ("latency_ms", "ci95_low_ms", "ci95_high_ms", "period_s", "frequency_hz", "seconds", "truth_ms", "error_ms")
        for row in rows:
            for key in numeric:
                if key in row:
                    row[key] = float(row[key]) if row[key] not in ("", None) else None
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise ConfigError(f"cannot read the summary {path}: {error}") from None
    return rows


def summary_report(path: Path, group: str | None = None) -> Report:
    """The comparison across the runs of a summary, grouped by a label."""
    rows = read_summary(path)
    if not rows:
        raise ConfigError(f"{path} holds no rows")
    labels = [key for key in rows[0] if key not in RESULT_COLUMNS]
    group = group or (labels[0] if labels else None)
    if group is not None and group not in rows[0]:
        raise ConfigError(f"no label {group!r} in {path}; labels: {', '.join(labels) or 'none'}")
    measured = [row for row in rows if row.get("latency_ms") is not None]
    failed = [row for row in rows if row.get("status") == "failed"]
    report = Report(f"Summary of {path}", f"{len(measured)} of {len(rows)} videos measured",
                    f"{len(failed)} failed, {sum(row.get('status') == 'warning' for row in rows)} with warnings")  # fmt: skip
    report.sections.append(Section("Latency per video", [("summary", summary_figure(rows, group))]))
    known = any(row.get("truth_ms") is not None for row in rows)
    truth_header = ("true (ms)", "error (ms)") if known else ()
    if group is not None:
        others = [label for label in labels if label != group]
        pooled = group_latencies(measured, group, others)
        table = [
            (g.name, *(value for _, value in g.conditions), g.videos, g.latency_ms, g.latency_ms - Z95 * g.se_ms, g.latency_ms + Z95 * g.se_ms,
             *((g.truth_ms, g.error_ms) if known else ()))
            for g in pooled
        ]  # fmt: skip
        pairs = [(f"{d.b} - {d.a}", *(value for _, value in d.conditions), d.difference_ms, *d.ci95_ms,
                  "differ" if d.differs else "not shown to differ") for d in differences(pooled)]  # fmt: skip
        report.sections.append(Section(f"By {group}", [
            f"Each group pooled over its videos, weighted by their intervals (rig.service.compare); only videos whose "
            f"other labels ({', '.join(others) or 'none'}) match are pooled, and only such groups compared.",
            ((group, *others, "videos", "latency (ms)", "95 % low", "95 % high", *truth_header), table),
            (("difference", *others, "ms", "95 % low", "95 % high", "verdict"), pairs),
        ]))  # fmt: skip
    table = [(row["video"], row.get("status"), *(row.get(label) for label in labels), row.get("latency_ms"), row.get("ci95_low_ms"),
              row.get("ci95_high_ms"), *((row.get("truth_ms"), row.get("error_ms")) if known else ()),
              row.get("warnings") or row.get("error") or "") for row in rows]  # fmt: skip
    header = ("video", "status", *labels, "latency (ms)", "95 % low", "95 % high", *truth_header, "warnings / error")
    report.sections.append(Section("Every video", [(header, table)]))
    report.sections.append(Section("Software", [(("software", "version"), software())]))
    return report


def check_report_path(out: Path) -> None:
    """Refuse, before any work, a report path that is not an .html file in an existing folder."""
    if out.suffix.lower() != ".html":
        raise ConfigError(f"--out must name an .html file (the Markdown goes beside it), got {out}")
    if not out.parent.is_dir():
        raise ConfigError(f"cannot write {out}: folder {out.parent} does not exist")


def write_report(report: Report, out: Path) -> tuple[Path, Path]:
    """The page at `out` (.html) and the Markdown beside it (.md); both paths."""
    out = Path(out)
    check_report_path(out)
    markdown = out.with_suffix(".md")
    write_html(report, out)
    write_markdown(report, markdown)
    return out, markdown
