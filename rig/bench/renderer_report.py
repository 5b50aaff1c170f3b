"""What the renderer benches (`rig.bench.renderers` and its companions) report: rows as JSON and
CSV, and the grid's table. The plots are in `rig.bench.renderer_plots`."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

from rig.errors import RigError


def _plain(value: Any) -> Any:
    """JSON has no infinity or NaN: they are written as null."""
    return None if isinstance(value, float) and not math.isfinite(value) else value


def write_json(rows: list[dict[str, Any]], path: Path) -> None:
    """The rows as a JSON list."""
    try:
        path.write_text(json.dumps([{k: _plain(v) for k, v in row.items()} for row in rows], indent=1) + "\n", encoding="utf-8")
    except OSError as error:
        raise RigError(f"cannot write {path}: {error}") from error


def write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    """The rows as CSV, one column per field any row has, in the order they first appear."""
    fields = list(dict.fromkeys(key for row in rows for key in row))
    try:
        with path.open("w", newline="") as stream:
            writer = csv.DictWriter(stream, fieldnames=fields)
            writer.writeheader()
            writer.writerows(rows)
    except OSError as error:
        raise RigError(f"cannot write {path}: {error}") from error


def _format(value: Any, digits: int = 1) -> str:
    if value is None:
        return "-"
    return f"{value:.{digits}f}" if isinstance(value, float) else str(value)


def table(rows: list[dict[str, Any]]) -> str:
    """The grid's rows as a fixed-width table, with the latency notes and the machine below."""
    lines = [
        f"{'renderer':8} {'N':>9} {'size':>9} {'ratio':>5} {'frame ms':>9} {'p95':>8} {'gpu ms':>7} {'cpu ms':>8} {'client ms':>9} "
        f"{'lat meas':>8} {'lat true':>8} {'sd':>5} {'missed':>6} {'Lab>10 %':>8} {'SSIM':>6} {'PSNR':>5} {'holes %':>7}"
    ]  # fmt: skip
    for r in rows:
        ratio = f"1:{r['rate_ratio']}" if r["rate_ratio"] else "-"
        missed = f"{r['missed_pct']:.0f}%" if r["missed_pct"] is not None else "-"
        lines.append(
            f"{r['renderer']:8} {r['triangles']:>9} {r['width']}x{r['height']:<4} {ratio:>5} {_format(r['frame_ms_median']):>9} "
            f"{_format(r['frame_ms_p95']):>8} {_format(r['frame_gpu_ms_median']):>7} {_format(r['frame_cpu_ms_median']):>8} "
            f"{_format(r['client_ms_median']):>9} "
            f"{_format(r['latency_measured_ms']):>8} {_format(r['latency_true_ms']):>8} {_format(r['latency_sd_ms']):>5} {missed:>6} "
            f"{_format(r['lab_error_pct'], 2):>8} {_format(r['ssim'], 3):>6} {_format(r['psnr_db']):>5} {_format(r['hole_pct'], 2):>7}"
        )
    specs = sorted({r["spec"] for r in rows if r["renderer"] == "warp"})
    lines.append(f"warp: {', '.join(specs)}; sd: the latency's spread swing by swing, from the video" if specs else "")
    lines += [f"latency: {note}" for note in sorted({r["latency_note"] for r in rows if r["latency_note"]})]
    lines.append(f"machine: {rows[0]['machine']}" if rows else "no rows")
    return "\n".join(lines)
