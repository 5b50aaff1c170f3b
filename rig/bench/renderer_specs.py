"""The renderer benches' specs, declared without their libraries: the grid of `rig bench renderers`
(`BenchGrid`, each setting declared once with its default, read from a TOML spec by `read_grid`),
and what its --seed-table mode measures (`SeedTableSpec`). The command line's options are checked
against these declarations (`rig.bench.renderers_settings`); the benches measure with them."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from declared import Range, check, from_table, like, setting
from rig.errors import ConfigError
from rig.sim.camera_config import CameraConfig
from rig.sim.config import MAX_HOURS, SimulationConfig
from rig.sim.display_config import DisplayConfig
from rig.toml_file import read_toml

QUICK_SPEC = Path(__file__).parent / "specs" / "renderers-quick.toml"

TRIANGLES = Range(0.0, 1e8, True, True)
"""A load's triangles: a heavy VR scene draws a few million a frame, 100 million is past any GPU's budget."""
TRIANGLES_PER_S = 1e9
"""Triangles a second the fastest GPU draws in small random triangles."""
PIXELS_PER_S = 1e10
"""Pixels a second the fastest GPU warps and reads back."""
FILMED_RENDERERS = 2
"""Each filmed load is filmed through the direct and the warp renderer."""


@dataclass(frozen=True)
class LatencyRun:
    """One filmed run: what it is, as a simulation (`config`: renderer, load, display, predictor,
    photon target, camera, and the costs modelled, None where measured), its shortest film and its
    longest pendulum period (how it is filmed is `rig.bench.renderer_latency.film_config`'s)."""

    config: SimulationConfig
    min_duration_s: float = 6.0
    max_period_s: float = 8.0


@dataclass(frozen=True)
class BenchGrid:
    """What `rig bench renderers` measures, and how much of it: each setting declared on its field
    (the defaults are the bench's grid); a spec file (`--spec FILE.toml`, `specs/renderers-quick.toml`)
    sets any of them, every key and value checked (`read_grid`)."""

    triangles: tuple[int, ...] = setting(
        (10_000, 100_000, 1_000_000, 5_000_000), "triangles",
        "load sizes (a soup of small random triangles), each timed at every resolution", TRIANGLES,
    )  # fmt: skip
    resolutions: tuple[tuple[int, int], ...] = setting(
        ((320, 240), (640, 480), (1280, 720)), "pixels", "display sizes, [width, height]; the first is the latency films' display too"
    )
    ratios: tuple[int, ...] = setting(
        (1, 5, 10), "", "client:display rate ratios 1:r whose image error is measured (display frames per client frame)",
        Range(1.0, 100.0, True, True),
    )  # fmt: skip
    warp: str = setting("warp", "", "the warp renderer and its options, a renderer spec such as warp:recon=grid,views=2")
    phases: int = setting(4, "", "client poses per load and resolution for the image error, spread over a swing",
                          Range(1.0, 1000.0, True, True))  # fmt: skip
    warp_rounds: int = setting(
        16, "", "rounds of warp timing; each round times one display frame of every load in turn", Range(1.0, 10000.0, True, True)
    )
    direct_frames: int = setting(4, "", "direct frames timed at most (the first is always timed)", Range(1.0, 10000.0, True, True))
    direct_budget_s: float = setting(6.0, "seconds", "no more direct frames are timed after this long", Range(0.0, 3600.0, includes_high=True))
    latency_triangles: tuple[int, ...] | None = setting(
        None, "triangles", "the load sizes whose latency is filmed", TRIANGLES, unset="all of them"
    )
    latency_camera: CameraConfig = CameraConfig()
    """the latency films' camera; its frame rate follows the pendulum's period"""
    latency_duration_s: float = setting(6.0, "seconds", "the latency films' shortest length", Range(0.5, 3600.0, True, True))
    max_period_s: float = setting(
        8.0, "seconds", "the longest pendulum period filmed: a latency that would need a longer one is beyond range",
        Range(0.2, 20.0, True, True),
    )
    refresh_hz: float = like(DisplayConfig, "refresh_hz", flag=None)
    server_ms: float | None = setting(
        None, "ms", "the warp server's modelled cost in the latency films", Range(0.0, 1000.0, includes_high=True), unset="measured here, as every other cost"
    )
    predictor: str = setting("hold", "", "the latency films' predictor, both renderers alike (as in Smit et al. 2010, Table 2)")
    direct_predictor: str | None = setting(
        None, "", "the direct renderer's predictor in the latency films, where it differs", unset="the same"
    )

    def __post_init__(self) -> None:
        check(self, ConfigError)
        if not (self.triangles and self.resolutions and self.ratios):
            raise ConfigError("a renderer bench grid needs at least one load size, resolution and rate ratio")
        if min(min(size) for size in self.resolutions) < 16:
            raise ConfigError(f"a display is at least 16x16 pixels, got {self.resolutions}")
        if (hours := self.estimated_hours()) > MAX_HOURS:
            raise ConfigError(f"this grid would take about {hours:.3g} hours at the least, more than the {MAX_HOURS:g} hours the rig "
                              "starts: fewer or smaller loads, resolutions, phases or warp rounds, or split it into grids of its own")  # fmt: skip

    def estimated_hours(self) -> float:
        """The least time the grid takes, in hours, so that a grid that cannot finish is refused with
        its estimate before any frame is drawn. The figures are generous on purpose (the fastest
        GPUs' rates): the estimate is a floor, so only a grid that no machine finishes within
        `rig.sim.config.MAX_HOURS` is refused. Each load at each resolution is drawn for its direct
        frames (at most the direct budget of time), its client frames and warps for the image error
        (`phases` poses, each warped at every ratio), and its warp rounds; each latency film renders
        its load at the display's refresh for at least its duration."""
        seconds = 0.0
        for width, height in self.resolutions:
            for triangles in self.triangles:
                frame_s = triangles / TRIANGLES_PER_S
                direct_s = min(self.direct_budget_s, self.direct_frames * frame_s)
                image_error_s = self.phases * (frame_s + len(self.ratios) * width * height / PIXELS_PER_S)
                rounds_s = self.warp_rounds * (frame_s + width * height / PIXELS_PER_S)
                seconds += direct_s + image_error_s + rounds_s
        filmed = self.latency_triangles if self.latency_triangles is not None else self.triangles
        film_frames = self.latency_duration_s * self.refresh_hz
        seconds += FILMED_RENDERERS * sum(film_frames * triangles / TRIANGLES_PER_S for triangles in filmed)
        return seconds / 3600.0

    def latency_run(
        self, renderer: str, triangles: int, predictor: str, photon_target: str = "photons", load: str = "soup"
    ) -> LatencyRun:
        """The filmed run of `renderer` on `triangles` (shaped as `load` says) at the first
        resolution, costs measured (the server's modelled if `server_ms` says)."""
        width, height = self.resolutions[0]
        config = SimulationConfig(
            display=DisplayConfig(refresh_hz=self.refresh_hz, width=width, height=height), renderer=renderer, predictor=predictor,
            scene_triangles=triangles, scene_load=load, app_frame_ms=None, warp_ms=self.server_ms, photon_target=photon_target,
            camera=self.latency_camera,
        )  # fmt: skip
        return LatencyRun(config, self.latency_duration_s, self.max_period_s)


def read_grid(path: Path | None) -> BenchGrid:
    """The grid a TOML spec sets (`declared.from_table`: every key and value checked, a typo or a
    wrong type one line naming the file and the key), the defaults where it is silent; with no
    spec, the defaults."""
    return from_table(BenchGrid, read_toml(path, "spec"), ConfigError, str(path)) if path is not None else BenchGrid()


@dataclass(frozen=True)
class SeedTableSpec:
    """What `--seed-table` measures: load sizes from `first` up to the limits, what the load makes,
    and the grid whose first resolution, direct-frame timing, films (camera, length, longest period,
    refresh), predictor, warp spec and server cost the table takes."""

    first: int = 4_000
    max_triangles: int = setting(
        20_000_000, "triangles", "the largest load (720 MB and the GL driver's copy)", Range(1.0, 1e8, True, True),
    )  # fmt: skip
    max_frame_s: float = setting(
        60.0, "seconds", "the largest direct frame a scene may take, at most ten minutes", Range(0.0, 600.0, includes_high=True),
    )  # fmt: skip
    load: str = "soup"
    """what the load's triangles make (`rig.render.gl.LOAD_SHAPES`): the soup is the stress case,
    meshes a few tessellated solid objects, as the seed's scenes were"""
    grid: BenchGrid = BenchGrid(resolutions=((320, 240),), direct_frames=3, direct_budget_s=2.0)

    def sizes(self) -> list[int]:
        """The fourfold series of load sizes up to `max_triangles` (the frame limit stops it earlier)."""
        sizes = [self.first]
        while sizes[-1] * 4 <= self.max_triangles:
            sizes.append(sizes[-1] * 4)
        return sizes
