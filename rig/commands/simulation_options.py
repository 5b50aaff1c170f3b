"""The options that describe a simulated rig and the lab's procedure (shared by `rig simulate` and
`rig demo`), made from `SimulationConfig`'s declarations (`rig.commands.declared_options`), and the
config they give. Some options are not a single setting: --predictor (the predictor and its
parameters), --board (the simulated board, with its defaults), and `rig simulate`'s calibration
target, --flash-hz or --flash-display (`add_flash_options`)."""

from __future__ import annotations

import argparse

from rig.commands import options
from rig.commands.choices import predictors_listing, renderers_listing
from rig.commands.declared_options import add_declared_options, config_from_args, declared_type
from rig.errors import ConfigError
from rig.session.run_files import BOARD_FOLDER
from rig.sim.board_config import SimulatedBoardConfig
from rig.sim.config import SimulationConfig
from rig.sim.flash_target import FlashTarget
from rig.sim.impairments_config import FILM

RIG = "simulated rig"
LAB = "lab"


def add_simulation_options(parser: argparse.ArgumentParser, lab: bool = False) -> None:
    """The options that describe a simulated rig; with `lab`, what a lab does during a filmed run
    too (release a held pendulum, blink the board's LED)."""
    parser.listings = lambda: "\n\n".join((renderers_listing(), predictors_listing()))
    groups = {"": RIG, FILM: "simulated camera's film"} | ({LAB: "lab procedure"} if lab else {})
    sections = add_declared_options(parser, SimulationConfig, groups)
    sections[RIG].add_argument(
        "--predictor",
        type=options.predictor_spec,
        default=(SimulationConfig().predictor, {}),
        metavar="NAME[:key=value,...]",
        help="pose predictor (listed below) and its parameters, or NAME:FILE.json (default: default, the adaptive predictor)",
    )
    if lab:
        board = SimulatedBoardConfig()
        sections["lab procedure"].add_argument(
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
    target.add_argument("--flash-hz", type=declared_type(FlashTarget, "hz"), metavar="F",
                        help="a white card lit by an LED flashing at F Hz fills the view")  # fmt: skip
    target.add_argument("--flash-display", type=declared_type(FlashTarget, "refreshes"), metavar="N",
                        help="the display flashes full-field: white for the first half of every N refreshes (N = 2 "
                        "alternates white and black), black for the rest")  # fmt: skip
    group.add_argument("--flash-duty", type=declared_type(FlashTarget, "duty"), default=light.duty, metavar="D",
                       help="with --flash-hz, the share of each period the LED is on (default: %(default)s)")  # fmt: skip


def _flash_target(args: argparse.Namespace) -> FlashTarget | None:
    """The calibration target the flash options ask for, if any."""
    if getattr(args, "flash_hz", None) is not None:
        return FlashTarget("light", hz=args.flash_hz, duty=args.flash_duty)
    if getattr(args, "flash_display", None) is not None:
        return FlashTarget("display", refreshes=args.flash_display)
    return None


def simulation_config(args: argparse.Namespace) -> SimulationConfig:
    """The simulated run the options ask for."""
    predictor, params = args.predictor
    board = SimulatedBoardConfig() if getattr(args, "board", False) else None
    return config_from_args(
        SimulationConfig, args, ConfigError, predictor=predictor, predictor_params=params, board=board, flash=_flash_target(args)
    )
