"""`rig report RUN_OR_SUMMARY --out report.html`: a page a lab can keep (and the same as Markdown)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rig.commands import outputs
from rig.errors import ConfigError
from rig.progress import ProgressBar

SUMMARY_SUFFIXES = (".csv", ".json")


def _run(args: argparse.Namespace) -> int:
    from rig.service.report import run_report, summary_report, write_report

    source: Path = args.source
    outputs.checked(outputs.output_file(".html"), args.out, "--out")
    if not source.exists():
        raise ConfigError(f"{source} does not exist; give a video, a run folder or a summary (.csv or .json)")
    if source.is_file() and source.suffix.lower() in SUMMARY_SUFFIXES:
        report = summary_report(source, args.group)
    else:
        report, _ = run_report(source, ProgressBar("analysing"))
    page, markdown = write_report(report, args.out)
    print(f"{report.headline}; {report.verdict}")
    print(f"wrote {page} and {markdown}")
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "report",
        description="For a video or a run folder (video.avi, with truth.json and board/ when the run has them): "
        "the latency in large type, the tracks over the whole film with the delayed LED laid on the sphere, the "
        "latency swing by swing, the residual, every method and diagnostic with its verdict, the warnings, the "
        "configuration, the software versions and the project's commit. For a summary (rig analyse --summary, "
        "rig sweep): the runs compared, grouped by a label. The page embeds its plots and needs no network; the "
        "Markdown beside it keeps its plots in a folder.",
    )
    parser.add_argument("source", type=Path, metavar="RUN_OR_SUMMARY", help="a video, a run folder, or a summary .csv/.json")
    parser.add_argument("--out", type=Path, required=True, metavar="REPORT.html", help="the page to write (REPORT.md goes beside it)")
    parser.add_argument("--group", metavar="LABEL", help="for a summary: the label to group by (default: the first label)")
    parser.set_defaults(func=_run)
