"""The options that describe a simulated rig and the lab's procedure (shared by `rig simulate` and
`rig demo`), and the config they give."""

from __future__ import annotations

import argparse
from dataclasses import replace

from rig.commands import options
from rig.commands.choices import predictors_listing, renderers_listing
from rig.service import SimulationConfig
from rig.session import PHOTON_TARGETS
from rig.film_file import CODECS, CONTAINERS, default_codec
from rig.sim.bench import DEFAULT_LAYOUT, LAYOUT_HELP
from rig.sim.board import BOARD_FOLDER, SimulatedBoardConfig
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.flash import FlashTarget
from rig.sim.impairments import OCCLUDABLE, FilmImpairments
from rig.sim.pendulum import MAX_AMPLITUDE_DEG, PendulumConfig
from rig.sim.tracker import TrackerConfig


def add_simulation_options(parser: argparse.ArgumentParser) -> None:
    """The options that describe a simulated rig (shared by `simulate` and `demo`)."""
    defaults = SimulationConfig()
    parser.epilog = "\n\n".join((renderers_listing(), predictors_listing()))
    group = parser.add_argument_group("simulated rig")
    group.add_argument(
        "--renderer",
        default=defaults.renderer,
        metavar="NAME[:key=value,...]",
        help="renderer under test (listed below) and its options, e.g. warp:views=2,recon=grid,holes=1 (default: %(default)s)",
    )
    group.add_argument(
        "--predictor",
        type=options.predictor_spec,
        default=(defaults.predictor, {}),
        metavar="NAME[:key=value,...]",
        help="pose predictor (listed below) and its parameters, or NAME:FILE.json (default: default, the adaptive predictor)",
    )
    group.add_argument("--display-hz", type=options.positive_float, default=DisplayConfig().refresh_hz, help="display refresh rate (default: %(default)s)")
    group.add_argument("--tracker-hz", type=options.positive_float, default=TrackerConfig().rate_hz, help="tracker sample rate (default: %(default)s)")
    group.add_argument("--camera-fps", type=options.positive_float, default=CameraConfig().fps, help="camera frame rate (default: %(default)s)")
    group.add_argument(
        "--exposure",
        type=_exposure_fraction,
        default=1.0,
        metavar="F",
        help="camera exposure as a fraction of the frame interval, in (0, 1] (default: %(default)s, the whole interval)",
    )
    group.add_argument(
        "--readout-ms",
        type=options.non_negative_float,
        default=CameraConfig().readout_s * 1e3,
        metavar="R",
        help="rolling shutter: row y of H starts exposing y/H x R ms after row 0, at most a frame interval "
        "(default: %(default)s, a global shutter)",
    )
    group.add_argument("--layout", default=DEFAULT_LAYOUT, metavar="LAYOUT", help=f"where the LED and the display sit in the frame: {LAYOUT_HELP} (default: %(default)s)")
    group.add_argument(
        "--display-phase",
        type=_refresh_fraction,
        default=DisplayConfig().phase,
        metavar="P",
        help="when the display's refreshes start against the camera's frames, as a fraction of a refresh "
        "in [0, 1) (default: %(default)s)",
    )
    group.add_argument("--duration", type=options.positive_float, default=defaults.duration_s, help="filmed seconds (default: %(default)s)")
    group.add_argument("--seed", type=int, default=defaults.seed, help="random seed; the same seed gives the same video (default: %(default)s)")
    group.add_argument("--scene-triangles", type=options.non_negative_int, default=0, help="load geometry drawn behind the sphere (default: 0)")
    group.add_argument(
        "--app-frame-ms",
        type=options.app_frame_cost,
        default=defaults.app_frame_ms,
        help="modelled application frame cost in ms, or 'measured' for the real GL time (default: %(default)s)",
    )
    group.add_argument(
        "--warp-ms",
        type=options.app_frame_cost,
        default=defaults.warp_ms,
        help="modelled cost of each image a compositing (warp) renderer composes, in ms, or 'measured' for the "
        "real GL time: a composition that takes longer than a refresh misses it (default: %(default)s)",
    )
    group.add_argument(
        "--predict-to",
        choices=PHOTON_TARGETS,
        default=defaults.photon_target,
        help="the instant each frame's pose is predicted for, at the sphere's row: 'photons' the middle of the "
        "interval the row emits it (scan-out plus half the persistence), 'scanout' when scan-out reaches the row "
        "(default: %(default)s)",
    )
    group.add_argument(
        "--persistence",
        type=options.positive_float,
        default=defaults.persistence,
        help="share of a refresh each display row emits a frame: 1 for sample-and-hold (the simulated display), "
        "less for a low-persistence panel (default: %(default)s)",
    )
    group.add_argument(
        "--transport-delay-ms",
        type=options.non_negative_float,
        default=TrackerConfig().transport_delay_s * 1e3,
        help="fixed tracker-to-host delay (default: %(default)s)",
    )
    group.add_argument("--period-s", type=options.positive_float, default=PendulumConfig().period_s, help="pendulum period (default: %(default)s)")
    group.add_argument("--amplitude-deg", type=amplitude_deg, default=PendulumConfig().amplitude_deg, help="swing amplitude, up to 45 (default: %(default)s)")
    group.add_argument("--quality", type=options.positive_float, default=PendulumConfig().quality, help="pendulum quality factor Q (default: %(default)s)")
    _add_camera_options(parser)


def _add_camera_options(parser: argparse.ArgumentParser) -> None:
    """What the simulated camera does to its film besides its rate and exposure (`rig.sim.impairments`)."""
    camera, film = CameraConfig(), FilmImpairments()
    group = parser.add_argument_group("simulated camera's film")
    group.add_argument("--noise-dn", type=options.non_negative_float, default=camera.noise_dn, help="sensor read noise, digital numbers (default: %(default)s)")
    group.add_argument(
        "--display-white-dn",
        type=options.positive_float,
        default=camera.display_white_dn,
        help="how bright the display's white films, digital numbers: lower for a dim sphere (default: %(default)s)",
    )
    group.add_argument("--blur-px", type=options.non_negative_float, default=film.blur_sigma_px, help="defocus blur, Gaussian sigma in pixels (default: %(default)s)")
    group.add_argument(
        "--dim-led",
        type=options.positive_float,
        default=film.dim_led,
        metavar="F",
        help="scale the LED's half of each frame by F in (0, 1], after the sensor saturates (default: %(default)s)",
    )
    group.add_argument("--mirrored", action="store_true", help="flip the film left to right: the LED on the right, the sphere on the left")
    group.add_argument(
        "--bright-object-dn",
        type=options.non_negative_float,
        default=film.bright_object_dn,
        help="a static lamp in view between and above the two halves, its peak in digital numbers (default: none)",
    )
    group.add_argument("--occluded", choices=OCCLUDABLE, default=None, help="a bar hiding part of this blob's path")
    group.add_argument(
        "--missing-fraction",
        type=options.non_negative_float,
        default=film.missing_fraction,
        metavar="F",
        help="hide the sphere in this share of the frames, drawn by the seed (default: %(default)s)",
    )
    group.add_argument("--container", choices=CONTAINERS, default=camera.container, help="the film's file (default: %(default)s)")
    group.add_argument("--codec", choices=CODECS, default=None, help="the film's codec (default: mjpeg in an avi, h264 in an mp4 or mov)")
    group.add_argument(
        "--frame-jitter-ms",
        type=options.non_negative_float,
        default=camera.frame_jitter_s * 1e3,
        metavar="J",
        help="start each exposure up to J/2 ms before or after its nominal time, drawn by the seed, as phones do; "
        "needs an mp4 or mov, which stamps each frame (default: %(default)s)",
    )
    group.add_argument("--every-nth", type=options.positive_int, default=film.every_nth, metavar="N", help="film every N-th exposure only (default: %(default)s)")
    group.add_argument(
        "--first-frame",
        type=options.non_negative_int,
        default=film.first_frame,
        metavar="K",
        help="with --every-nth, the first exposure filmed, 0 to N - 1 (default: %(default)s)",
    )


def amplitude_deg(text: str) -> float:
    """A pendulum's swing in degrees, as far as the simulated pendulum goes."""
    value = options.positive_float(text)
    if value > MAX_AMPLITUDE_DEG:
        raise argparse.ArgumentTypeError(f"a swing is at most {MAX_AMPLITUDE_DEG:g} degrees, got {text}")
    return value


def _exposure_fraction(text: str) -> float:
    value = options.positive_float(text)
    if value > 1.0:
        raise argparse.ArgumentTypeError(f"an exposure is at most the whole frame interval (1), got {text}")
    return value


def _refresh_fraction(text: str) -> float:
    value = options.non_negative_float(text)
    if value >= 1.0:
        raise argparse.ArgumentTypeError(f"a display phase is a fraction of a refresh below 1, got {text}")
    return value


def config_from_args(args: argparse.Namespace) -> SimulationConfig:
    predictor, params = args.predictor
    return SimulationConfig(
        duration_s=args.duration,
        seed=args.seed,
        pendulum=PendulumConfig(period_s=args.period_s, amplitude_deg=args.amplitude_deg, quality=args.quality),
        tracker=TrackerConfig(rate_hz=args.tracker_hz, transport_delay_s=args.transport_delay_ms / 1e3),
        display=DisplayConfig(refresh_hz=args.display_hz, phase=args.display_phase),
        camera=CameraConfig(
            fps=args.camera_fps,
            exposure_s=args.exposure / args.camera_fps,
            noise_dn=args.noise_dn,
            readout_s=args.readout_ms / 1e3,
            frame_jitter_s=args.frame_jitter_ms / 1e3,
            container=args.container,
            codec=args.codec or default_codec(args.container),
            display_white_dn=args.display_white_dn,
            impairments=FilmImpairments(
                blur_sigma_px=args.blur_px,
                dim_led=args.dim_led,
                mirrored=args.mirrored,
                bright_object_dn=args.bright_object_dn,
                occluded=args.occluded,
                missing_fraction=args.missing_fraction,
                every_nth=args.every_nth,
                first_frame=args.first_frame,
            ),
        ),
        renderer=args.renderer,
        predictor=predictor,
        predictor_params=params,
        scene_triangles=args.scene_triangles,
        app_frame_ms=args.app_frame_ms,
        warp_ms=args.warp_ms,
        photon_target=args.predict_to,
        persistence=args.persistence,
        layout=args.layout,
    )


def add_lab_options(parser: argparse.ArgumentParser) -> None:
    """What a lab does during a filmed run: release a held pendulum, blink the board's LED."""
    board = SimulatedBoardConfig()
    group = parser.add_argument_group("lab procedure")
    group.add_argument(
        "--release-s",
        type=options.non_negative_float,
        default=None,
        metavar="S",
        help="hold the pendulum at rest at its amplitude and release it S seconds into the film "
        "(at least one swing before the end; default: swinging from the start)",
    )
    group.add_argument(
        "--board",
        action="store_true",
        help=f"simulate the rig board: it plays the LED blink code ({board.blink_bits} bits of "
        f"{board.blink_bit_s * 1e3:g} ms from {board.blink_start_s:g} s of film; the film must last until "
        f"{board.blink_end_s:g} s) and records its LED changes and the pendulum encoder on its own clock "
        f"({board.board_offset_s:g} s ahead) in DIR/{BOARD_FOLDER}/, as `rig board record` does",
    )


def add_flash_options(parser: argparse.ArgumentParser) -> None:
    """A calibration target filmed instead of the bench (`rig.sim.flash`), for `rig calibrate-camera`."""
    light = FlashTarget()
    group = parser.add_argument_group(
        "calibration target",
        "Film a flashing light instead of the bench, to measure the camera's readout and exposure with "
        "`rig calibrate-camera` (the pendulum, tracker and renderer still run, unseen).",
    )
    target = group.add_mutually_exclusive_group()
    target.add_argument("--flash-hz", type=options.positive_float, metavar="F",
                        help="a white card lit by an LED flashing at F Hz fills the view")  # fmt: skip
    target.add_argument("--flash-display", type=_flash_refreshes, metavar="N",
                        help="the display flashes full-field: white for the first half of every N refreshes (N = 2 "
                        "alternates white and black), black for the rest")  # fmt: skip
    group.add_argument("--flash-duty", type=_duty, default=light.duty, metavar="D",
                       help="with --flash-hz, the share of each period the LED is on (default: %(default)s)")  # fmt: skip


def with_flash_options(config: SimulationConfig, args: argparse.Namespace) -> SimulationConfig:
    """The config with the calibration target the flash options ask for, if any."""
    if args.flash_hz is not None:
        return replace(config, flash=FlashTarget("light", hz=args.flash_hz, duty=args.flash_duty))
    if args.flash_display is not None:
        return replace(config, flash=FlashTarget("display", refreshes=args.flash_display))
    return config


def _flash_refreshes(text: str) -> int:
    value = options.positive_int(text)
    if value < 2:
        raise argparse.ArgumentTypeError(f"a flashing display needs at least 2 refreshes a period, got {text}")
    return value


def _duty(text: str) -> float:
    value = options.positive_float(text)
    if value >= 1.0:
        raise argparse.ArgumentTypeError(f"a duty cycle is a share of each period below 1, got {text}")
    return value


def with_lab_options(config: SimulationConfig, args: argparse.Namespace) -> SimulationConfig:
    """The config with the release and board that the lab options ask for."""
    return replace(
        config,
        pendulum=replace(config.pendulum, release_s=args.release_s),
        board=SimulatedBoardConfig() if args.board else None,
    )
