"""Many measurements at once: analyse a batch of videos into one summary, on any executor.

Every video becomes one row (`SUMMARY_COLUMNS`, plus the labels the user gave): `status` is `ok`,
`warning` (measured, but read the warnings, or ambiguous) or `failed` (with the reason in
`error`); one bad video never stops the batch. Rows reach the summary CSV as each video finishes,
so an interrupted batch keeps what it finished; the JSON beside it (`partial: true` until the end)
holds the same rows. At the end both are rewritten in the order the videos were given, so a batch
gives the same summary, row for row, serially or on Dask.
"""

from __future__ import annotations

import glob
import json
import os
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

from analysis import LatencyResult
from analysis.video.native_path import shown_path
from rig.errors import ConfigError, user_errors
from rig.executor import executor
from rig.fresh_outputs import removed_unless_recorded
from rig.writers import CsvRecord
from rig.service.analyse import AnalysisRequest, analyse

VIDEO_SUFFIXES = (".avi", ".mp4", ".mov", ".mkv", ".m4v", ".webm")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")
SUMMARY_COLUMNS = (
    "index", "video", "status", "latency_ms", "ci95_low_ms", "ci95_high_ms", "method", "model", "period_s",
    "frequency_hz", "frames", "frames_used", "ambiguous", "warnings", "error", "seconds",
)  # fmt: skip
USER_ERRORS = user_errors()
RESULT_COLUMNS = frozenset((*SUMMARY_COLUMNS, "truth_ms", "error_ms"))
"""Every column a summary row may hold that is not a label (a sweep adds the truth and the error)."""


@dataclass(frozen=True)
class BatchItem:
    """One video to analyse and the labels its row carries (for grouping and comparing)."""

    request: AnalysisRequest
    labels: dict[str, str] = field(default_factory=dict)


def find_videos(paths: Sequence[str | Path]) -> list[Path]:
    """The videos that paths, folders and glob patterns name, in the order given (a folder's in name
    order). A folder holding video files gives each of them; a folder of images is one video."""
    found: list[Path] = []
    for entry in paths:
        matches = sorted(glob.glob(str(entry))) if glob.has_magic(str(entry)) else [str(entry)]
        if not matches:
            raise ConfigError(f"nothing matches {entry}")
        for match in map(Path, matches):
            videos = sorted(p for p in match.iterdir() if p.suffix.lower() in VIDEO_SUFFIXES) if match.is_dir() else []
            found.extend(videos or [match])
    return list(dict.fromkeys(found))


def labels_from(path: Path | None, videos: Sequence[Path]) -> dict[Path, dict[str, str]]:
    """Labels per video from a CSV whose first column is `video` (a path as given, or a file name)
    and whose other columns are labels; without one, each video is labelled by its folder."""
    if path is None:
        return {video: {"folder": shown_path(video.parent.name) or "."} for video in videos}
    import csv

    try:
        with open(path, newline="", encoding="utf-8") as stream:
            rows = list(csv.DictReader(stream))
    except OSError as error:
        raise ConfigError(f"cannot read the labels {path}: {error.strerror}") from None
    if not rows or "video" not in rows[0]:
        raise ConfigError(f"{path} must be a CSV whose first column is video, then one column per label")
    by_name = {row["video"]: {k: v for k, v in row.items() if k != "video"} for row in rows}
    return {video: by_name.get(str(video), by_name.get(video.name, {})) for video in videos}


def analysed_row(item: BatchItem) -> tuple[dict[str, Any], LatencyResult | None]:
    """Analyse one video into its summary row (a failure is a row too, never an exception), and the
    analyser's whole result (None where the row failed)."""
    started = time.perf_counter()
    row: dict[str, Any] = dict.fromkeys(SUMMARY_COLUMNS)
    row["video"] = shown_path(item.request.video)
    result = None
    try:
        result = analyse(item.request).result
    except USER_ERRORS as error:
        row.update(status="failed", error=str(error))
    except Exception as error:
        where = traceback.extract_tb(error.__traceback__)[-1]
        row.update(
            status="failed",
            error=f"unexpected {type(error).__name__} at {Path(where.filename).name}:{where.lineno}: {error} "
            "(a bug: please report it with this video)",
        )
    else:
        low, high = result.ci95_ms if result.ci95_ms is not None else (None, None)
        row.update(
            status="warning" if result.warnings or result.ambiguous else "ok",
            latency_ms=result.latency_ms,
            ci95_low_ms=low,
            ci95_high_ms=high,
            method=result.method,
            model=result.model,
            period_s=result.period_s,
            frequency_hz=1.0 / result.period_s,
            frames=result.frames,
            frames_used=result.frames_used,
            ambiguous=result.ambiguous,
            warnings="; ".join(warning.replace("\n", ", ") for warning in result.warnings),  # a cell of one line
        )
    row["seconds"] = time.perf_counter() - started
    return row | item.labels, result


def _write_json(path: Path, rows: list[dict[str, Any]], partial: bool) -> None:
    temporary = path.with_name(path.name + ".tmp")
    temporary.write_text(json.dumps({"partial": partial, "rows": rows}, indent=1) + "\n", encoding="utf-8")
    os.replace(temporary, path)


@dataclass
class BatchRun:
    """A batch's rows so far, recorded into `summary` (and its JSON) as they come."""

    summary: Path | None
    columns: tuple[str, ...]
    rows: list[dict[str, Any]] = field(default_factory=list)
    _record: CsvRecord | None = None

    def open(self) -> None:
        if self.summary is not None:
            self._record = CsvRecord(self.summary, self.columns, overwrite=True)

    def add(self, row: dict[str, Any]) -> None:
        self.rows.append(row)
        if self._record is not None:
            self._record.write([row.get(column) for column in self.columns])
            _write_json(self.summary.with_suffix(".json"), self.rows, partial=True)

    def finish(self) -> list[dict[str, Any]]:
        """The rows in input order, and the summary rewritten so."""
        self.rows.sort(key=lambda row: row["index"])
        if self.summary is not None:
            self.close()
            temporary = self.summary.with_name(self.summary.name + ".tmp")
            with CsvRecord(temporary, self.columns, overwrite=True) as record:
                for row in self.rows:
                    record.write([row.get(column) for column in self.columns])
            os.replace(temporary, self.summary)
            _write_json(self.summary.with_suffix(".json"), self.rows, partial=False)
        return self.rows

    def close(self) -> None:
        if self._record is not None:
            self._record.close()
            self._record = None

    def run(
        self,
        job: Callable[[Any], dict[str, Any]],
        items: Sequence[Any],
        workers: int | None,
        scheduler: str | None,
        progress: Callable[[float, float], object] | None,
    ) -> list[dict[str, Any]]:
        """Each item's row by `job`, serially, on `workers` local Dask processes or on `scheduler`,
        added as it comes; the rows in input order."""
        self.open()
        try:
            with executor(workers, scheduler) as jobs:
                for _, row in jobs(job, items):
                    self.add(row)
                    if progress is not None:
                        progress(len(self.rows), len(items))
            return self.finish()
        finally:
            self.close()


def _indexed(pair: tuple[int, BatchItem]) -> dict[str, Any]:
    index, item = pair
    return analysed_row(item)[0] | {"index": index}


def run_batch(
    items: Sequence[BatchItem],
    summary: Path | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[float, float], object] | None = None,
) -> list[dict[str, Any]]:
    """Analyse every item (serially, on `workers` local Dask processes, or on `scheduler`); the rows
    in input order. The summary CSV and JSON are written as rows come (see the module docstring)."""
    labels = list(dict.fromkeys(key for item in items for key in item.labels))
    run = BatchRun(summary, (*SUMMARY_COLUMNS, *labels))
    outputs = () if summary is None else (summary, summary.with_suffix(".json"))
    if progress is not None:
        progress(0, len(items))
    with removed_unless_recorded(*outputs):
        return run.run(_indexed, list(enumerate(items)), workers, scheduler, progress)


def write_summary_plot(rows: Sequence[dict[str, Any]], path: Path, group: str | None) -> None:
    """The batch's latencies with their intervals per video, coloured by the label `group`, and
    against swing frequency where the videos' periods differ."""
    from rig.report.figures import summary_figure

    summary_figure(rows, group).savefig(path, dpi=110)
