"""The renderer benches' plots: latency against scene size with image error against warp time (the
grid), this machine's latencies beside the seeds' Table 2, image error against latency saved per
warp variant."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

from rig.bench.contract import new_figure


def _draw(path: Path, draw: Callable[[Any, list[Any]], None]) -> None:
    """A figure of two panels side by side, drawn by `draw(figure, axes)` and saved to `path`."""
    figure, axes = new_figure((12, 4.8), nrows=1, ncols=2)
    draw(figure, list(axes))
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def _legend_or_say(axis: Any, nothing: str) -> None:
    """The axis's legend where anything is drawn on it; else (every row failed) only `nothing`, said in words."""
    if axis.get_legend_handles_labels()[0]:
        axis.legend(fontsize=8)
        return
    axis.clear()
    axis.set_axis_off()
    axis.text(0.5, 0.5, nothing, ha="center", va="center", transform=axis.transAxes)


def _latency_series(axis: Any, rows: list[dict[str, Any]], renderer: str, colour: str, label: str, marker: str = "o", filled: bool = True) -> None:
    points = {r["triangles"]: r for r in rows if r["renderer"] == renderer and r["latency_measured_ms"] is not None}
    n = sorted(points)
    if n:
        axis.errorbar(n, [points[k]["latency_measured_ms"] for k in n], yerr=[points[k]["latency_sd_ms"] or 0.0 for k in n],
                      marker=marker, color=colour, capsize=3, label=label, mfc=colour if filled else "none")  # fmt: skip


def plot_rows(rows: list[dict[str, Any]], path: Path) -> None:
    """The grid: latency against N for both renderers, and image error against warp time."""

    def draw(figure: Any, axes: list[Any]) -> None:
        left, right = axes
        for renderer, colour in (("direct", "tab:red"), ("warp", "tab:blue")):
            _latency_series(left, rows, renderer, colour, f"{renderer}, measured from video")
            points = sorted((r["triangles"], r["latency_true_ms"]) for r in rows if r["renderer"] == renderer and r["latency_true_ms"] is not None)
            if points:
                left.plot(*zip(*points), "x--", color=colour, alpha=0.6, label=f"{renderer}, true")
            unmeasured = {r["triangles"]: "failed" if r["failed"] else "beyond range" for r in rows if r["renderer"] == renderer
                          and (r["failed"] or str(r["latency_note"]).startswith("beyond"))}  # fmt: skip
            for k, why in sorted(unmeasured.items()):
                left.annotate(why, (k, 1.0), xycoords=("data", "axes fraction"), ha="center", va="top", color=colour, fontsize=8, rotation=90)
        left.set(xscale="log", yscale="log", xlabel="load triangles", ylabel="latency (ms); bars: sd swing by swing",
                 title="latency against scene size, costs measured")  # fmt: skip
        _legend_or_say(left, "no latency was measured\n(the table says why)")
        warp = [r for r in rows if r["renderer"] == "warp" and r["frames_timed"] is not None]
        for (width, height), marker in zip(sorted({(r["width"], r["height"]) for r in warp}), "os^Dv"):
            for ratio, colour in zip(sorted({r["rate_ratio"] for r in warp}), ("tab:green", "tab:orange", "tab:purple", "tab:brown")):
                chosen = [r for r in warp if (r["width"], r["height"], r["rate_ratio"]) == (width, height, ratio)]
                right.scatter([r["frame_ms_median"] for r in chosen], [r["lab_error_pct"] for r in chosen], marker=marker,
                              color=colour, label=f"{width}x{height}, client:display 1:{ratio}")  # fmt: skip
        right.set(xlabel="warp time per display frame (ms, median)", ylabel="pixels with Lab error > 10 (%)",
                  title="image error against warp time (one point per N)")  # fmt: skip
        _legend_or_say(right, "no load was timed\n(the table says why)")

    _draw(path, draw)


def plot_seed_table(ours: list[dict[str, Any]], seed: list[dict[str, Any]], path: Path, label: str) -> None:
    """Latency against scene size, ours and the seed's; and latency against the direct frame time,
    both in refreshes of each one's display. `label` says what ours measured (load, warp spec)."""

    def draw(figure: Any, axes: list[Any]) -> None:
        left, right = axes
        for rows, filled, who in ((ours, True, "this machine"), (seed, False, "seed Table 2")):
            for renderer, colour in (("direct", "tab:red"), ("warp", "tab:blue")):
                _latency_series(left, rows, renderer, colour, f"{renderer}, {who}", "o" if filled else "s", filled)
                frame = {r["triangles"]: r["frame_ms_median"] / r["refresh_ms"] for r in rows
                         if r["renderer"] == "direct" and r["frame_ms_median"] is not None}  # fmt: skip
                points = sorted((frame[r["triangles"]], r["latency_refreshes"]) for r in rows
                                if r["renderer"] == renderer and r["latency_refreshes"] is not None and r["triangles"] in frame)  # fmt: skip
                if points:
                    right.plot(*zip(*points), marker="o" if filled else "s", color=colour, mfc=colour if filled else "none",
                               label=f"{renderer}, {who}")  # fmt: skip
        left.set(xscale="log", yscale="log", xlabel="scene triangles", ylabel="latency (ms), bars: sd",
                 title=f"latency against scene size, measured by filming\nthis machine: {label}")  # fmt: skip
        right.set(xscale="log", yscale="log", xlabel="direct frame time (display refreshes)", ylabel="latency (display refreshes)",
                  title="machine-independent: both in refreshes")  # fmt: skip
        _legend_or_say(left, "no latency was measured\n(the table says why)")
        _legend_or_say(right, "no latency was measured\n(the table says why)")

    _draw(path, draw)


def plot_variants(rows: list[dict[str, Any]], path: Path) -> None:
    """Image error (Lab > 10 share, and DSSIM) against latency saved, one point per variant and scene."""

    def draw(figure: Any, axes: list[Any]) -> None:
        specs = list(dict.fromkeys(r["spec"] for r in rows))
        sizes = sorted({r["triangles"] for r in rows})
        markers = dict(zip(specs, "osD^v<>pPX*hH8d"))
        colours = dict(zip(sizes, ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")))
        for axis, figure_name, label in zip(axes, ("lab_error_pct", "dssim"), ("pixels with Lab error > 10 (%)", "DSSIM")):
            for r in rows:
                if r["latency_saved_ms"] is not None and r["spec"] in markers:
                    axis.scatter(r["latency_saved_ms"], r[figure_name], marker=markers[r["spec"]], color=colours[r["triangles"]])
            axis.set(xlabel="latency saved against the direct renderer (ms, from video)", ylabel=label,
                     title=f"{label} against latency saved")  # fmt: skip
        handles = [axes[0].scatter([], [], marker=m, color="k", label=spec) for spec, m in markers.items()]
        handles += [axes[0].scatter([], [], marker="s", color=c, label=f"{n} triangles") for n, c in colours.items()]
        axes[1].legend(handles=handles, fontsize=7, loc="best")

    _draw(path, draw)
