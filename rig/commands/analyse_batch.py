"""`rig analyse` of many videos (several paths, folders, globs, or `--summary`): one summary row per
video, serially or on Dask, written as each video finishes (see `rig.service.batch`)."""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import sys

from rig.cli import EXIT_USER_ERROR, EXIT_WARNINGS
from rig.commands import outputs
from rig.errors import ConfigError
from rig.progress import ProgressBar
from rig.service import AnalysisRequest
from rig.service.batch import BatchItem, labels_from, run_batch, write_summary_plot


def is_batch(args: argparse.Namespace, videos: list[Path]) -> bool:
    """Many videos, or any option that only a batch has."""
    return len(videos) > 1 or any(value is not None for value in (args.summary, args.workers, args.scheduler))


def check_batch_options(args: argparse.Namespace) -> None:
    """Options that name one video's outputs have no meaning for many; refuse them before any work."""
    for option, value in (("--csv", args.csv), ("--board", args.board)):
        if value is not None:
            raise ConfigError(f"{option} is for one video; a batch writes its rows with --summary FILE.csv")
    if args.summary is not None and args.summary.exists() and not args.overwrite:
        raise ConfigError(f"{args.summary} already exists; choose another file or pass --overwrite")
    if args.plot is not None and args.summary is None:
        raise ConfigError("--plot of a batch needs --summary FILE.csv (the plot shows the summary's rows)")


def _line(row: dict[str, Any]) -> str:
    if row["status"] == "failed":
        return f"{row['video']}: failed: {row['error']}"
    interval = f" (95% CI {row['ci95_low_ms']:.2f} to {row['ci95_high_ms']:.2f} ms)" if row["ci95_low_ms"] is not None else ""
    flag = " [warnings]" if row["status"] == "warning" else ""
    return f"{row['video']}: {row['latency_ms']:.2f} ms{interval} by {row['method']}{flag}"


def run_batch_command(args: argparse.Namespace, template: AnalysisRequest, videos: list[Path]) -> int:
    """Exit 0 when every video measured cleanly, 3 when any failed or came with warnings, 2 when every
    one failed (its summary written, with why)."""
    labels = labels_from(args.labels, videos)
    names = list(dict.fromkeys(name for values in labels.values() for name in values))
    if args.group is not None and args.group not in names:
        raise ConfigError(f"--group {args.group}: no such label (labels: {', '.join(names) or 'none'})")
    group = args.group or next(iter(names), None)
    items = [BatchItem(replace(template, video=video), labels[video]) for video in videos]
    progress = ProgressBar("analysing", unit="videos")
    rows = run_batch(items, args.summary, args.workers, args.scheduler, progress)
    plot = args.plot or (args.summary.with_suffix(".png") if args.summary is not None else None)
    if args.json:
        print(json.dumps(rows))
    else:
        for row in rows:
            print(_line(row))
        counts = {status: sum(row["status"] == status for row in rows) for status in ("ok", "warning", "failed")}
        print(f"{len(rows)} videos: {counts['ok']} ok, {counts['warning']} with warnings, {counts['failed']} failed")
        if args.summary is not None:
            print(f"summary: {args.summary}, {args.summary.with_suffix('.json')} and the plot {plot}")
    if plot is not None:
        writes = outputs.LateWrites()
        writes.write(plot, lambda: write_summary_plot(rows, plot, group))
        writes.check()
    if rows and all(row["status"] == "failed" for row in rows):
        print(f"rig analyse: error: every one of the {len(rows)} videos failed (the first: {rows[0]['error']})", file=sys.stderr)
        return EXIT_USER_ERROR
    return 0 if all(row["status"] == "ok" for row in rows) else EXIT_WARNINGS
