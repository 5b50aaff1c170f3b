"""Sweeps: simulate-then-analyse every point of a grid over the simulation's options, on any executor,
into the same summary a batch writes (`rig.service.batch`), with each point's settings as labels and
the simulation's truth and the error beside the measured latency.

A sweep is a TOML file:

    [base]                       # SimulationConfig fields; nested ones as tables or dotted keys
    duration_s = 6.0
    camera.fps = 240.0

    [grid]                       # every combination of these values
    "pendulum.period_s" = [0.8, 1.0, 1.4]
    predictor = ["hold", "slerp"]

    [[points]]                   # and/or points given one by one, after the grid's
    labels = { case = "dim LED" } # the row's labels (default: the settings the point names)
    camera.impairments.dim_led = 0.35

    [analysis]                   # how each video is analysed (analysis.AnalysisOptions' fields)
    method = "sinefit"
    simulated_rois = true        # the LED's and the sphere's regions the simulation knows
    bench = "bench.toml"         # a bench profile, from the sweep's folder: its values are hints
    simulated_bench = true       # or each point's own bench: its camera, display and LED's side

A sweep needs a [grid] or [[points]] or both; each point is the base with its settings over it.
A cost (app_frame_ms, warp_ms) given as "measured" is this machine's GL time, as `rig simulate
--app-frame-ms measured` takes it. With `simulated_rois`, each video is analysed within the regions
where its simulation put the LED and the sphere (truth.json), as a lab marks them once for its
camera, instead of the analyser finding them. With `simulated_bench`, each video's hints are its own
simulation's camera (frame rate, exposure, readout), display (refresh rate, scan-out top-down) and
the LED's side, as a lab whose bench profile is right gives them, each checked against the film as
any profile's are. `write_sweep` writes a sweep in this form.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

from analysis import AnalysisError, AnalysisOptions, LatencyResult
from analysis.video.native_path import shown_path
from declared import from_table, setting_of
from rig.errors import ConfigError
from rig.film_file import video_file_name
from rig.fresh_outputs import removed_unless_recorded
from rig.service.analyse import AnalysisRequest
from rig.service.batch import SUMMARY_COLUMNS, USER_ERRORS, BatchItem, BatchRun, analysed_row
from rig.service.bench_profile import BenchProfile, CameraProfile, DisplayProfile, LayoutProfile, read_profile, with_profile
from rig.service.simulate import TRUTH_FILE, SimulationResult, simulate
from rig.sim.config import SimulationConfig
from rig.sim.placement import placement
from rig.sim.truth import Truth
from rig.toml_file import dotted, read_toml

SIMULATED_ROIS = "simulated_rois"
"""The [analysis] option that analyses each video within its simulation's regions."""
SIMULATED_BENCH = "simulated_bench"
"""The [analysis] option that gives each video its own simulation's bench as hints."""
FLAGS = (SIMULATED_ROIS, SIMULATED_BENCH)
MAX_POINTS = 10_000
"""The most points a sweep runs: more is a grid written by mistake (each point is a film simulated
and analysed, seconds to minutes each), counted before any point is made."""
BENCH = "bench"
"""The [analysis] option naming a bench profile (`rig.service.bench_profile`; a path from the sweep's
folder), whose values are each video's hints, as `rig analyse --bench` takes them."""


@dataclass(frozen=True)
class SweepPoint:
    """One point of a sweep: its simulation, its labels (the grid's values, or an explicit point's),
    its run folder, its analysis, and whether that takes the simulation's regions (SIMULATED_ROIS)
    and its bench (SIMULATED_BENCH)."""

    index: int
    config: SimulationConfig
    labels: dict[str, str]
    out_dir: Path
    analysis: AnalysisRequest
    simulated_rois: bool = False
    simulated_bench: bool = False


@dataclass(frozen=True)
class Sweep:
    """base: settings every point shares; grid: settings and the values each takes (every
    combination is a point); explicit: points given one by one (dotted settings, and optionally
    their labels under "labels"); analysis: `AnalysisOptions` settings, and the FLAGS."""

    base: dict[str, Any]
    grid: dict[str, list[Any]]
    analysis: dict[str, Any] = field(default_factory=dict)
    explicit: list[dict[str, Any]] = field(default_factory=list)

    def settings(self) -> list[tuple[dict[str, Any], dict[str, str]]]:
        """Each point's settings over the base's, and its labels: the grid's points, then the explicit."""
        names = list(self.grid)
        combinations = itertools.product(*(self.grid[name] for name in names)) if names else ()
        chosen = [(dict(zip(names, values)), None) for values in combinations]
        chosen += [({k: v for k, v in point.items() if k != "labels"}, point.get("labels")) for point in self.explicit]
        return [
            (_merged(self.base, overrides), {str(k): str(v) for k, v in (labels if labels is not None else dotted(overrides)).items()})
            for overrides, labels in chosen
        ]

    @property
    def labels(self) -> list[str]:
        """The label columns of the summary: every label any point has, in order of appearance."""
        return list(dict.fromkeys(name for _, labels in self.settings() for name in labels))

    def only(self, keep: Callable[[dict[str, str]], bool]) -> Sweep:
        """The sweep of the points whose labels `keep` accepts, each given explicitly."""
        return Sweep({}, {}, self.analysis, [{**settings, "labels": labels} for settings, labels in self.settings() if keep(labels)])

    def points(self, out: Path) -> list[SweepPoint]:
        options = analysis_options(self.analysis)
        rois, bench = (bool(self.analysis.get(flag, False)) for flag in FLAGS)
        points = []
        for index, (settings, labels) in enumerate(self.settings()):
            folder = out / f"point{index:03d}"
            config = build(SimulationConfig, settings)
            request = AnalysisRequest(folder / video_file_name(config.camera.container), options)
            points.append(SweepPoint(index, config, labels, folder, request, rois, bench))
        return points


def analysis_options(table: Mapping[str, Any]) -> AnalysisOptions:
    """The analysis options a sweep's [analysis] table gives (besides FLAGS), every key and
    value checked, with the hints of the bench profile it names (BENCH)."""
    try:
        options = from_table(
            AnalysisOptions, {k: v for k, v in table.items() if k not in (*FLAGS, BENCH)}, AnalysisError, "[analysis]"
        )
    except AnalysisError as error:
        raise ConfigError(str(error)) from None
    if BENCH not in table:
        return options
    path = Path(table[BENCH])
    return with_profile(options, read_profile(path), path)


def _merged(base: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    return {**dotted(base), **dotted(overrides)}


def build(kind: type, settings: Mapping[str, Any]) -> Any:
    """A config dataclass from dotted settings (`camera.fps`), every key and value checked against
    its declaration (`declared.from_table`)."""
    table: dict[str, Any] = {}
    for key, value in settings.items():
        *parents, name = key.split(".")
        level = table
        for depth, parent in enumerate(parents):
            level = level.setdefault(parent, {})
            if not isinstance(level, dict):
                raise ConfigError(f"the sweep's {'.'.join(parents[: depth + 1])} must be a table of settings ({key} among them), not {level!r}")
        level[name] = value
    return from_table(kind, table, ConfigError, "the sweep")


def settings_of(config: Any, default: Any = None) -> dict[str, Any]:
    """A point's settings that make `config`: the fields that differ from the defaults (`default`,
    else the config's class's), nested configs as tables; None as its setting's word (MEASURED)."""
    default = type(config)() if default is None else default
    settings: dict[str, Any] = {}
    for field_ in dataclasses.fields(config):
        value, usual = getattr(config, field_.name), getattr(default, field_.name)
        declared = setting_of(field_)
        if value == usual:
            continue
        if dataclasses.is_dataclass(value):
            settings[field_.name] = settings_of(value, usual if usual is not None else type(value)())
        elif value is None and declared is not None and declared.none:
            settings[field_.name] = declared.none
        elif value is None:
            raise ConfigError(f"a sweep cannot set {field_.name} back to None")
        else:
            settings[field_.name] = list(value) if isinstance(value, tuple) else value
    return settings


def _toml_value(value: Any) -> str:
    """`value` in TOML: a table inline, a string as JSON writes it (TOML reads its escapes), a
    number as Python writes it (it reads back as the same number)."""
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + " }" if value else "{}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (int, float)):
        return repr(value)
    raise ConfigError(f"a sweep cannot hold {value!r}")


def _toml_key(key: str) -> str:
    return key if key.replace("_", "").replace("-", "").isalnum() and key.isascii() else json.dumps(key)


def write_sweep(sweep: Sweep, path: Path, comment: str = "") -> None:
    """The sweep as a TOML file `read_sweep` reads back as the same sweep, `comment` above it."""
    lines = [f"# {line}".rstrip() for line in comment.splitlines()]
    for table, values in (("base", sweep.base), ("grid", sweep.grid), ("analysis", sweep.analysis)):
        if values:
            lines += ["", f"[{table}]", *(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in values.items())]
    for point in sweep.explicit:
        lines += ["", "[[points]]", *(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in point.items())]
    try:
        Path(path).write_text("\n".join(lines).lstrip("\n") + "\n", encoding="utf-8")
    except OSError as error:
        raise ConfigError(f"cannot write the sweep {path}: {error.strerror}") from None


def read_sweep(path: Path) -> Sweep:
    """A sweep from its TOML file; ConfigError naming what is wrong."""
    spec = read_toml(path, "sweep")
    unknown = set(spec) - {"base", "grid", "points", "analysis"}
    if unknown:
        raise ConfigError(f"{path}: unknown table(s) {', '.join(sorted(unknown))}; a sweep has [base], [grid], [[points]] and [analysis]")
    for table in ("base", "grid", "analysis"):
        if not isinstance(spec.get(table, {}), dict):
            raise ConfigError(f"{path}: {table} must be a table ([{table}]) of settings, not {spec[table]!r}")
    grid = dotted(spec.get("grid", {}))
    explicit = spec.get("points", [])
    if not grid and not explicit:
        raise ConfigError(f"{path} has no [grid] and no [[points]]: name at least one setting and the values to sweep it over")
    for name, values in grid.items():
        if not isinstance(values, list) or not values:
            raise ConfigError(f"{path}: grid.{name} must be a non-empty list of values")
    if not isinstance(explicit, list) or not all(isinstance(point, dict) for point in explicit):
        raise ConfigError(f"{path}: points must be a list of tables ([[points]]), each a point's settings")
    count = math.prod(len(values) for values in grid.values()) * bool(grid) + len(explicit)
    if count > MAX_POINTS:
        sizes = " x ".join(str(len(values)) for values in grid.values())
        raise ConfigError(
            f"{path} has {count} points ({sizes} in the grid, {len(explicit)} given one by one), more than the "
            f"{MAX_POINTS} a sweep runs: sweep fewer values, or split it into sweeps of its own"
        )
    for number, point in enumerate(explicit, 1):
        if "labels" in point and not isinstance(point["labels"], dict):
            raise ConfigError(f"{path}: point {number}'s labels must be a table of names and values")
    analysis = spec.get("analysis", {})
    if BENCH in analysis and analysis.get(SIMULATED_BENCH, False):
        raise ConfigError(f"{path}: [analysis] gives both a {BENCH} profile and {SIMULATED_BENCH}: keep one")
    if BENCH in analysis:
        if not isinstance(analysis[BENCH], str):
            raise ConfigError(f"{path}: [analysis] {BENCH} is the path of a bench profile, not {analysis[BENCH]!r}")
        analysis = {**analysis, BENCH: str(Path(path).parent / analysis[BENCH])}
    try:
        analysis_options(analysis)
    except ConfigError as error:
        raise ConfigError(f"{path}: {error}") from None
    for flag in FLAGS:
        if not isinstance(analysis.get(flag, False), bool):
            raise ConfigError(f"{path}: [analysis] {flag} is true or false, not {analysis[flag]!r}")
    return Sweep(spec.get("base", {}), grid, analysis, explicit)


@dataclass(frozen=True)
class PointRun:
    """A point simulated and analysed: its summary row, the simulation, the options its video was
    analysed with, and the analyser's whole result (None where the row failed)."""

    row: dict[str, Any]
    simulation: SimulationResult
    options: AnalysisOptions
    result: LatencyResult | None


def told_options(point: SweepPoint, truth: Truth) -> AnalysisOptions:
    """The options the point's video is analysed with: the spec's, and where the point says, the
    simulation's regions and its own bench as hints."""
    options = point.analysis.options
    if point.simulated_rois:
        options = dataclasses.replace(options, led_roi=tuple(truth.led_roi), sphere_roi=tuple(truth.sphere_roi))
    if point.simulated_bench:
        options = with_profile(options, simulated_bench(point.config), point.out_dir / TRUTH_FILE)
    return options


def simulate_and_analyse(point: SweepPoint) -> PointRun:
    """Simulate one point and analyse its video (`told_options`): its summary row, with the truth
    and the error, and what made it."""
    simulation = simulate(point.config, point.out_dir, overwrite=True)
    truth = simulation.truth
    options = told_options(point, truth)
    row, result = analysed_row(BatchItem(dataclasses.replace(point.analysis, options=options), point.labels))
    row["index"] = point.index
    row["truth_ms"] = truth.latency_ms
    row["error_ms"] = row["latency_ms"] - truth.latency_ms if row["latency_ms"] is not None else None
    return PointRun(row, simulation, options, result)


def simulated_bench(config: SimulationConfig) -> BenchProfile:
    """The bench profile of a simulated run, as a lab that knows its bench writes it."""
    camera, source = config.camera, "the simulation"
    place = placement(config.layout)
    left = place.led[0] < place.display[0]
    return BenchProfile(
        CameraProfile(
            fps=camera.film_fps, fps_source=source, exposure_ms=camera.exposure * 1e3, exposure_source=source,
            readout_ms=camera.readout_s * 1e3, readout_source=source,
        ),
        DisplayProfile(refresh_hz=config.display.refresh_hz, refresh_source=source, scanout="top-down", scanout_source=source),
        LayoutProfile(led_side="left" if left != camera.impairments.mirrored else "right", source=source),
    )  # fmt: skip


def unsimulated_row(point: SweepPoint, error: Exception) -> dict[str, Any]:
    """The summary row of a point whose simulation was refused before it ran (a film too short to
    analyse, a film rate its container does not hold): failed, with the reason."""
    row = dict.fromkeys(SUMMARY_COLUMNS) | {"truth_ms": None, "error_ms": None}
    row.update(index=point.index, video=shown_path(point.analysis.video), status="failed", error=f"not simulated: {error}", seconds=0.0)
    return row | point.labels


def run_point(point: SweepPoint) -> dict[str, Any]:
    """Simulate one point and analyse its video: its summary row, with the truth and the error; a
    point that cannot be simulated is a failed row, not the end of the sweep."""
    try:
        return simulate_and_analyse(point).row
    except USER_ERRORS as error:
        return unsimulated_row(point, error)


def run_sweep(
    sweep: Sweep,
    out: Path,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[float, float], object] | None = None,
    overwrite: bool = False,
    job: Callable[[SweepPoint], dict[str, Any]] = run_point,
) -> tuple[list[dict[str, Any]], Path]:
    """Every point of the sweep into out/pointNNN, and the summary out/summary.csv (and .json); a
    folder that holds a sweep already is refused unless `overwrite`. `job` measures a point: its
    row (`run_point`'s, or a bench's, which adds to it; the CSV keeps the sweep's columns)."""
    points = sweep.points(Path(out))
    summary = Path(out) / "summary.csv"
    held = [path.name for path in (summary, *(point.out_dir for point in points)) if path.exists()]
    if held and not overwrite:
        raise ConfigError(f"{out} already holds a sweep ({', '.join(held[:3])}{', ...' if len(held) > 3 else ''}); "
                          "choose another folder or pass --overwrite")  # fmt: skip
    run = BatchRun(summary, (*SUMMARY_COLUMNS, "truth_ms", "error_ms", *sweep.labels))
    with removed_unless_recorded(Path(out)):
        Path(out).mkdir(parents=True, exist_ok=True)
        return run.run(job, points, workers, scheduler, progress), summary
