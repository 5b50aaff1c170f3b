"""Simulate the rig: a session on a virtual clock with the simulated devices, and the run's truth.

A run writes into its output folder as it goes (`rig.session.run_record`): `tracker.csv`,
`app_frames.csv`, `display_frames.csv`, `video.avi` and `camera_frames.csv` (or the camera's
`video.mp4` or `video.mov` with `frame_times.csv` too, `rig.film_file`), with a simulated board its
recording in `board/` (`rig.sim.board`), and at the end `truth.json` (`rig.sim.truth`). A folder
that already holds a run is refused unless `overwrite` is given.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import predictors
from analysis.phase import MIN_CYCLES
from analysis.shutter.estimate import MIN_FRAMES as MIN_FLASH_FRAMES
from analysis.windows import MIN_SAMPLES
from rig.clock import VirtualClock
from rig.devices.registry import DeviceContext, make_camera, make_display, make_tracker
from rig.errors import RigError
from rig.film_file import FRAME_TIMES_FILE, check_film_rate, video_file_name
from rig.film_formats import STAMPED_CONTAINERS
from rig.fresh_outputs import removed_unless_recorded
from rig.render import RenderSetup, make_renderer
from rig.session import RUN_FILES, PhotonTarget, RunRecord, Session, SessionParts, cost_model, timing_for
from rig.session.session import Progress
from rig.sim.board import BOARD_FOLDER, remove_recording
from rig.sim.config import SimulationConfig
from rig.sim.truth import FilmTruth, Truth, run_truth
from rig.sim.world import SimulatedWorld

TRUTH_FILE = "truth.json"
SIMULATION_FILES = (*RUN_FILES, *map(video_file_name, STAMPED_CONTAINERS), FRAME_TIMES_FILE, TRUTH_FILE, BOARD_FOLDER)
MIN_FILM_FRAMES = round(MIN_CYCLES * MIN_SAMPLES)
"""The fewest frames of a pendulum film: the analyser fits each swing on at least MIN_SAMPLES frames,
and at least MIN_CYCLES swings (`analysis.windows`, `analysis.phase`); a flashing light's film needs
`analysis.shutter`'s MIN_FRAMES."""


@dataclass(frozen=True)
class SimulationResult:
    """Where a simulated run wrote its files, and its truth."""

    out_dir: Path
    video_path: Path
    truth: Truth

    def summary(self) -> dict[str, Any]:
        """The run in brief, JSON-ready."""
        truth = self.truth
        return {
            "out_dir": str(self.out_dir),
            "video": str(self.video_path),
            "latency_ms": truth.latency_ms,
            "display_frame_delay_ms": {"mean": truth.display_frame_delay_ms.mean, "sd": truth.display_frame_delay_ms.sd},
            "refreshes": {"shown": truth.refreshes.shown, "missed": truth.refreshes.missed},
            "app_frame_cost": truth.app_frame_cost,
            "display_frame_cost": truth.display_frame_cost,
            "photon_target": {"mode": truth.config.photon_target, "persistence": truth.config.persistence},
            "frames": truth.frames,
            "camera_fps": truth.camera_fps,
            "led_roi": truth.led_roi,
            "sphere_roi": truth.sphere_roi,
        }

    def cost_line(self) -> str:
        """What the run's renderer cost on the clock and how many refreshes it missed, in one line."""
        truth = self.truth
        parts = [f"application frame {_cost_text(truth.app_frame_cost)}"]
        if truth.display_frame_cost is not None:
            parts.append(f"composed image {_cost_text(truth.display_frame_cost)}")
        refreshes = truth.refreshes
        return f"costs: {', '.join(parts)}; {refreshes.missed} of {refreshes.shown} refreshes missed (repeated the last image)"


def _cost_text(cost: dict[str, Any]) -> str:
    if cost["source"] == "modelled":
        return f"{cost['ms']:g} ms (modelled)"
    if not cost["frames"]:
        return "measured (none drawn)"
    return f"measured, median {cost['median_ms']:.1f} ms, largest {cost['max_ms']:.1f} ms"


def _prepare(out_dir: Path, overwrite: bool) -> None:
    """Make the output folder; refuse one holding a run unless `overwrite`, and then clear the old
    run's board recording (its files only)."""
    if out_dir.exists() and not out_dir.is_dir():
        raise RigError(f"{out_dir} is a file, not a folder; choose an output folder")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise RigError(f"cannot make the output folder {out_dir}: {error.strerror}") from None
    existing = [name for name in SIMULATION_FILES if (out_dir / name).exists()]
    if existing and not overwrite:
        raise RigError(f"{out_dir} already holds a run ({', '.join(existing)}); choose another output folder or pass --overwrite")
    if overwrite:
        remove_recording(out_dir / BOARD_FOLDER)


def _check_film(config: SimulationConfig, frames: int) -> None:
    """RigError, before the run, unless the film's container holds its rate and it holds enough
    frames to analyse."""
    camera = config.camera
    check_film_rate(camera.film_fps, camera.container, advice=", or in an MP4 or a MOV (--container mp4)")
    least = MIN_FLASH_FRAMES if config.flash is not None else MIN_FILM_FRAMES
    if frames < least:
        kept = f" (every {camera.impairments.every_nth}-th exposure)" if camera.impairments.every_nth > 1 else ""
        raise RigError(
            f"the film would hold {frames} frame{'' if frames == 1 else 's'}{kept}, too few to analyse: "
            f"a film needs at least {least}; film longer, or keep more of the exposures (a smaller --every-nth)"
        )


def _film_truth(config: SimulationConfig, world: SimulatedWorld, film_times: np.ndarray) -> FilmTruth:
    """How the camera filmed: its readout, where the blobs sit on average over the film, its file."""
    led_row, sphere_row = world.layout.mean_rows(world.pendulum.led_position(film_times))
    camera = config.camera
    return FilmTruth(
        readout_ms=camera.readout_s * 1e3,
        led_row=led_row,
        sphere_row=sphere_row,
        container=camera.container,
        codec=camera.film[1],
        frame_times=FRAME_TIMES_FILE if camera.container in STAMPED_CONTAINERS else None,
    )


def simulate(
    config: SimulationConfig,
    out_dir: Path,
    progress: Progress | None = None,
    overwrite: bool = False,
) -> SimulationResult:
    """Run the simulated rig of `config` and write its video, samples, frame logs and truth into out_dir."""
    out_dir = Path(out_dir)
    world = SimulatedWorld(config)
    context = DeviceContext(world.twins())
    display, camera = world.display(), world.camera()  # the registry's `sim` devices, whose details the truth reads
    _check_film(config, len(camera.film_times))
    renderer = make_renderer(config.renderer)
    board = world.board(out_dir / BOARD_FOLDER)
    timing = timing_for(renderer, cost_model(config.warp_ms))
    setup = RenderSetup(
        width=config.display.width,
        height=config.display.height,
        world_to_clip=world.layout.world_to_clip,
        sphere_radius_m=world.layout.sphere_radius_m,
        scene_triangles=config.scene_triangles,
        scene_load=config.scene_load,
        wait_for_gpu=config.app_frame_ms is None,
        seed=config.seed,
    )
    app_cost = cost_model(config.app_frame_ms)
    parts = SessionParts(
        clock=VirtualClock(world.t_begin),
        tracker=make_tracker("sim", context),
        predictor=predictors.make(config.predictor, **config.predictor_params),
        renderer=renderer,
        render_setup=setup,
        timing=timing,
        app_cost=app_cost,
        display=make_display("sim", context),
        camera=make_camera("sim", context),
        instruments=[board] if board is not None else [],
        target=PhotonTarget(config.photon_target, config.persistence),
    )
    with removed_unless_recorded(out_dir):
        _prepare(out_dir, overwrite)
        with RunRecord(out_dir, overwrite=overwrite, film=config.camera.film) as record:
            log = Session(parts, world.t_begin, world.t_end, record, progress).run()
        filmed = record.film.frames if record.film is not None else 0
        if filmed != len(camera.film_times):
            raise RigError(
                f"{record.video_path} holds {filmed} of the camera's {len(camera.film_times)} frames; the run's truth is not written"
            )
        impairments = config.camera.impairments
        truth = run_truth(
            config,
            world.pendulum,
            display,
            log,
            camera_span=(0.0, float(camera.frame_times[-1] + camera.frame_span_s)),
            frames=len(camera.film_times),
            rois=(list(impairments.film_rect(world.layout.led_roi, camera.width)), list(impairments.film_rect(world.layout.sphere_roi, camera.width))),
            costs=(app_cost.describe(log.app_costs_s), timing.display_frame_cost()),
            board=board.truth() if board is not None else None,
            film=None if config.films_by_default() else _film_truth(config, world, camera.film_times),
        )
        truth.write(out_dir / TRUTH_FILE)
    return SimulationResult(out_dir, record.video_path, truth)
