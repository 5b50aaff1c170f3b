"""The renderer grid's rows (`rig.bench.renderers`) as the printed table, and whether every one failed.

A row whose load could not be drawn has no figures, only `failed` (its reason); a row whose latency
film failed has its timings, "failed" where the latency would be, and its reason below the table."""

from __future__ import annotations

from typing import Any

from rig.bench.contract import cell


def table(rows: list[dict[str, Any]]) -> str:
    """The grid's rows as a fixed-width table, with the latency notes, the films that failed and the machine below."""
    lines = [
        f"{'renderer':8} {'N':>9} {'size':>9} {'ratio':>5} {'frame ms':>9} {'p95':>8} {'gpu ms':>7} {'cpu ms':>8} {'client ms':>9} "
        f"{'lat meas':>8} {'lat true':>8} {'sd':>5} {'missed':>6} {'Lab>10 %':>8} {'SSIM':>6} {'PSNR':>5} {'holes %':>7}"
    ]  # fmt: skip
    for r in rows:
        ratio = f"1:{r['rate_ratio']}" if r["rate_ratio"] else "-"
        if r["frames_timed"] is None:
            lines.append(f"{r['renderer']:8} {r['triangles']:>9} {r['width']}x{r['height']:<4} {ratio:>5} failed: {r['failed']}")
            continue
        missed = f"{r['missed_pct']:.0f}%" if r["missed_pct"] is not None else "-"
        lines.append(
            f"{r['renderer']:8} {r['triangles']:>9} {r['width']}x{r['height']:<4} {ratio:>5} {cell(r['frame_ms_median']):>9} "
            f"{cell(r['frame_ms_p95']):>8} {cell(r['frame_gpu_ms_median']):>7} {cell(r['frame_cpu_ms_median']):>8} "
            f"{cell(r['client_ms_median']):>9} "
            f"{'failed' if r['failed'] else cell(r['latency_measured_ms']):>8} {cell(r['latency_true_ms']):>8} {cell(r['latency_sd_ms']):>5} {missed:>6} "
            f"{cell(r['lab_error_pct'], '.2f'):>8} {cell(r['ssim'], '.3f'):>6} {cell(r['psnr_db']):>5} {cell(r['hole_pct'], '.2f'):>7}"
        )
    specs = sorted({r["spec"] for r in rows if r["renderer"] == "warp"})
    lines.append(f"warp: {', '.join(specs)}; sd: the latency's spread swing by swing, from the video" if specs else "")
    lines += [f"latency: {note}" for note in sorted({r["latency_note"] for r in rows if r["latency_note"]})]
    films_failed = {(r["renderer"], r["triangles"], r["failed"]) for r in rows if r["failed"] and r["frames_timed"] is not None}
    lines += [f"failed: the latency film of {renderer} on {n} triangles: {reason}" for renderer, n, reason in sorted(films_failed)]
    lines.append(f"machine: {rows[0]['machine']}" if rows else "no rows")
    return "\n".join(lines)


def untimed_rows(where: dict[str, Any], warp: str, ratios: tuple[int, ...], reason: str) -> list[dict[str, Any]]:
    """The rows of a load that could not be timed at one display size (`where`: the row's fields so
    far, the load and size among them), direct and warp at each rate ratio, each failed with `reason`."""
    failed = {**where, "failed": reason}
    return [{**failed, "renderer": "direct", "spec": "direct"}, *({**failed, "renderer": "warp", "spec": warp, "rate_ratio": r} for r in ratios)]


def every_row_failed(rows: list[dict[str, Any]]) -> str | None:
    """A sentence where every row failed (its load could not be timed, or its latency film
    failed), else None."""
    if not rows or any(r["failed"] is None for r in rows):
        return None
    return f"every one of the {len(rows)} rows failed (the first: {rows[0]['renderer']} on {rows[0]['triangles']} triangles: {rows[0]['failed']})"
