"""What the renderer bench (`rig.bench.renderers`) reports: its rows as CSV, a table and a plot."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

from rig.bench.renderers import ROW_FIELDS
from rig.errors import RigError


def write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    with path.open("w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=ROW_FIELDS)
        writer.writeheader()
        writer.writerows(rows)


def plot_rows(rows: list[dict[str, Any]], path: Path) -> None:
    """Latency against N for both renderers, and image error against warp time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    for renderer, colour in (("direct", "tab:red"), ("warp", "tab:blue")):
        points = {
            r["triangles"]: r for r in rows if r["renderer"] == renderer and r["latency_measured_ms"] is not None
        }
        n = sorted(points)
        if n:
            left.errorbar(n, [points[k]["latency_measured_ms"] for k in n], yerr=[points[k]["latency_sd_ms"] for k in n],
                          marker="o", color=colour, capsize=3, label=f"{renderer}, measured from video")  # fmt: skip
            left.plot(n, [points[k]["latency_true_ms"] for k in n], "x--", color=colour, alpha=0.6, label=f"{renderer}, true")
        beyond = sorted({r["triangles"] for r in rows if r["renderer"] == renderer and str(r["latency_note"]).startswith("beyond")})
        for k in beyond:
            left.annotate("beyond range", (k, 1.0), xycoords=("data", "axes fraction"), ha="center", va="top",
                          color=colour, fontsize=8, rotation=90)  # fmt: skip
    left.set_xscale("log")
    left.set_yscale("log")
    left.set_xlabel("load triangles")
    left.set_ylabel("latency (ms); bars: sd of the per-frame delay")
    left.set_title("latency against scene size")
    left.legend(fontsize=8)
    warp = [r for r in rows if r["renderer"] == "warp"]
    for (width, height), marker in zip(sorted({(r["width"], r["height"]) for r in warp}), "os^Dv"):
        for ratio, colour in zip(sorted({r["rate_ratio"] for r in warp}), ("tab:green", "tab:orange", "tab:purple", "tab:brown")):
            chosen = [r for r in warp if (r["width"], r["height"], r["rate_ratio"]) == (width, height, ratio)]
            right.scatter([r["frame_ms_median"] for r in chosen], [r["lab_error_pct"] for r in chosen], marker=marker,
                          color=colour, label=f"{width}x{height}, client:display 1:{ratio}")  # fmt: skip
    right.set_xlabel("warp time per display frame (ms, median)")
    right.set_ylabel("pixels with Lab error > 10 (%)")
    right.set_title("image error against warp time (one point per N)")
    right.legend(fontsize=8)
    figure.tight_layout()
    try:
        figure.savefig(path, dpi=110)
    except OSError as error:
        raise RigError(f"cannot write the plot {path}: {error}") from error
    finally:
        plt.close(figure)


def _format(value: Any, digits: int = 1) -> str:
    if value is None:
        return "-"
    return f"{value:.{digits}f}" if isinstance(value, float) else str(value)


def table(rows: list[dict[str, Any]]) -> str:
    """The rows as a fixed-width table, with the latency notes and the machine below."""
    lines = [
        f"{'renderer':8} {'N':>9} {'size':>9} {'ratio':>5} {'frame ms':>9} {'p95':>8} {'gpu ms':>7} {'cpu ms':>8} {'client ms':>9} "
        f"{'lat meas':>8} {'lat true':>8} {'sd':>5} {'Lab>10 %':>8} {'PSNR':>5} {'holes %':>7}"
    ]  # fmt: skip
    for r in rows:
        ratio = f"1:{r['rate_ratio']}" if r["rate_ratio"] else "-"
        lines.append(
            f"{r['renderer']:8} {r['triangles']:>9} {r['width']}x{r['height']:<4} {ratio:>5} {_format(r['frame_ms_median']):>9} "
            f"{_format(r['frame_ms_p95']):>8} {_format(r['frame_gpu_ms_median']):>7} {_format(r['frame_cpu_ms_median']):>8} "
            f"{_format(r['client_ms_median']):>9} "
            f"{_format(r['latency_measured_ms']):>8} {_format(r['latency_true_ms']):>8} {_format(r['latency_sd_ms']):>5} "
            f"{_format(r['lab_error_pct'], 2):>8} {_format(r['psnr_db']):>5} {_format(r['hole_pct'], 2):>7}"
        )
    lines += [f"latency: {note}" for note in sorted({r["latency_note"] for r in rows if r["latency_note"]})]
    lines.append(f"machine: {rows[0]['machine']}" if rows else "no rows")
    return "\n".join(lines)
