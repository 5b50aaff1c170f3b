"""The `rig` command line. Every user error ends in one line on stderr and exit status 2.

This module imports only the standard library, the rig's error types and its interrupt handling
(`rig.interrupts`), so that an interrupt or a signal at any moment, imports included, ends in the
rig's own message and exit status: the command modules are imported once the handlers are in place.
`rig --help` lists the commands from COMMANDS and imports none of them; `rig COMMAND` imports that
command's module alone, whose parser is made from light declarations (settings dataclasses, the
help's listings): numpy, OpenCV, JAX, SciPy, matplotlib and the analysis load only once the command
runs, so that any help answers at once. `rig --version` is the installed package's.

Exit statuses: 0 a clean result; EXIT_WARNINGS (3) measured, but read the warnings (`rig analyse`:
an interval widened or corrected for how the camera samples the display, a model misfit, missing
frames; `rig measure`: a run whose health is degraded, or a video that misses the whole run's
latency; the number stands, with its caveats printed); EXIT_UNTRUSTED (4) `rig measure`: the
run's own health makes it invalid (the rig or its tracker stalled), so the stall is printed and no
latency; `rig check`: a device failed its check; EXIT_USER_ERROR (2) bad input, or a video that
cannot be measured; EXIT_INTERRUPTED (130) and EXIT_TERMINATED (143) a run stopped, its records
kept; EXIT_FAULT (1) a fault of the rig's own, printed with its traceback. A few commands give 1 a meaning of their own: `rig demo` and
`rig measure` a disagreement, `rig tune` parameters not written, `rig plan` no setting that reaches
the accuracy. A sweep, a batch (`rig analyse` of many videos) or a bench whose every item failed
exits EXIT_USER_ERROR, after writing its summary with why each failed: there is no number to read.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import textwrap
import traceback
from typing import Callable, NoReturn, Sequence

from rig import interrupts
from rig.compile_cache import keep_compiled_fits
from rig.errors import user_errors
from rig.interrupts import Terminated

COMMANDS = {
    "demo": "simulate the rig end to end and check the analyser against the known latency",
    "simulate": "simulate the rig and write a video with known latency",
    "analyse": "measure latency from a video of the LED and the sphere",
    "calibrate-camera": "measure a camera's readout and exposure from a film of a flashing light",
    "plan": "recommend the camera setting, film length and layout that reach a latency accuracy",
    "sweep": "simulate and analyse a grid of simulated rigs into one summary",
    "report": "write a self-contained HTML report (and Markdown) of a run or of a summary of many",
    "bench": "benchmarks: speed against error, as JSON and a plot",
    "tune": "fit a predictor's parameters to recorded motion; keep them only if they beat the defaults on motion held out",
    "board": "the rig's microcontroller: identity, clock sync, recording, blink, latency",
    "record-tracker": "record a serial, HID or LSL tracker's samples on the host's clock, as they arrive",
    "devices": "list the serial ports, HID devices and LSL streams this machine sees",
    "emulate-tracker": "an emulated tracker (serial over a pty or TCP, or LSL) for tests and demos, with faults on demand",
    "record": "film with a camera (device, file or stream), every frame written as it comes",
    "measure": "measure a real system: the live rig and a camera together, then the latency from the video beside the rig's log",
    "check": "check the devices a run would use (display refresh and pacing, camera rate and exposure, tracker, disk) in about 10 s",
}
"""Each command and its line in `rig --help`, in the order it lists them, kept here so that listing the
commands imports none of them; its module in rig.commands is named after it (`command_module`)."""
OTHER_MODULE_NAMES = {"emulate-tracker": "emulate"}
"""The commands whose module is not their name with underscores."""
PACKAGE = "latency-rig"
"""The distribution whose installed metadata `rig --version` reads."""
EXIT_FAULT = 1
"""A fault of the rig's own (not of the input): its traceback is printed, with REPORT_A_FAULT."""
REPORT_A_FAULT = (
    "this is a fault in the rig itself, not in what you asked for; please report it to the rig's maintainers "
    "with the command line and the traceback above"
)
EXIT_USER_ERROR = 2
EXIT_WARNINGS = 3
EXIT_UNTRUSTED = 4
"""A live run that cannot be trusted (it stalled), or a device that failed `rig check`: distinct
from a bench or input at fault (2)."""
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143


class ListingFormatter(argparse.HelpFormatter):
    """Wraps help text as argparse does, except a paragraph that lists choices (lines indented by
    two spaces after its title), which keeps a line per choice, and never inside a hyphenated word
    (an option's or a layout's name reads whole)."""

    def _split_lines(self, text: str, width: int) -> list[str]:
        return textwrap.wrap(" ".join(text.split()), width, break_on_hyphens=False)

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        return "\n\n".join(
            part if "\n  " in part else super(ListingFormatter, self)._fill_text(part, width, indent)
            for part in text.split("\n\n")
        )


class OneLineParser(argparse.ArgumentParser):
    """The rig's parser: help that lists choices a line each, and a usage error in one line (the
    option as typed, what was wrong, where the help is), exit status 2.

    `listings` makes the help's epilog (the predictors, renderers or methods a command takes) when
    the help is shown, not when the parser is built: listing a registry imports what it lists.
    """

    def __init__(self, *args: object, listings: Callable[[], str] | None = None, **kwargs: object) -> None:
        kwargs.setdefault("formatter_class", ListingFormatter)
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.listings = listings

    def format_help(self) -> str:
        if self.listings is not None:
            self.epilog = self.listings()
        return super().format_help()

    def error(self, message: str) -> NoReturn:
        option = re.match(r"argument (--[\w-]+).*: expected one argument", message)
        if option is not None:
            message += f" (write a value that starts with '-' as {option[1]}=VALUE)"
        self.exit(EXIT_USER_ERROR, f"{self.prog}: error: {message}; see {self.prog} --help\n")


class VersionAction(argparse.Action):
    """`--version`: the installed package's version, read from its metadata only when asked."""

    def __init__(self, option_strings: list[str], dest: str = argparse.SUPPRESS, **kwargs: object) -> None:
        super().__init__(option_strings, dest, nargs=0, help="print the rig's version and exit")

    def __call__(self, parser: argparse.ArgumentParser, *args: object) -> NoReturn:
        print(f"{parser.prog} {installed_version()}")
        parser.exit(0)


def installed_version() -> str:
    """The version pip installed, or what to do when the rig runs from a tree that is not installed."""
    from importlib import metadata  # here, not above: reading it costs as much as the rest of `rig --help`

    try:
        return metadata.version(PACKAGE)
    except metadata.PackageNotFoundError:
        return "(version unknown: not installed; run `pip install -e .` in the rig's folder)"


def command_module(name: str) -> str:
    """The module of the command `name`: its parser and what it runs."""
    return "rig.commands." + OTHER_MODULE_NAMES.get(name, name.replace("-", "_"))


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The command line. When `argv` names a command, that command's parser alone is built from
    its module; otherwise every command is listed by its summary (COMMANDS) and no command module
    is imported, so `rig --help` answers at once."""
    parser = OneLineParser(
        prog="rig",
        description="Measure motion-to-photon latency with a pendulum, an LED and a camera; simulate the rig.",
    )
    parser.add_argument("--version", action=VersionAction)
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    named = next((word for word in argv or () if not word.startswith("-")), None)
    if named in COMMANDS:
        importlib.import_module(command_module(named)).add_parser(subparsers)
    else:
        for name, summary in COMMANDS.items():
            subparsers.add_parser(name, help=summary)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    with interrupts.deferred():  # the commands' imports load native extensions
        args = build_parser(argv).parse_args(argv)
    try:
        return args.func(args)
    except user_errors() as error:
        print(f"rig {args.command}: error: {error}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt as interrupt:
        interrupts.handled()
        return _stopped(type(interrupt), f"rig {args.command}", "; everything recorded so far is on disk")


def _stopped(kind: type[KeyboardInterrupt], who: str, then: str) -> int:
    """Say on stderr that `who` was terminated or interrupted (`kind`), and what `then` holds; the exit status."""
    terminated = issubclass(kind, Terminated)
    print(f"\n{who}: {'terminated' if terminated else 'interrupted'}{then}", file=sys.stderr)
    return EXIT_TERMINATED if terminated else EXIT_INTERRUPTED


def run() -> None:
    """Console-script entry point.

    Ends with os._exit once the command has closed its files: an interrupt that lands while native
    code (XLA, OpenCV, OpenGL) runs its own exit handlers or threads could otherwise crash or hang
    the interpreter's teardown after the work is safely on disk.
    """
    interrupts.install()
    try:
        keep_compiled_fits()
        code = main()
        late = interrupts.pending()
        if late is not None:
            # Swallowed where it landed and never raised again: the work ran to its end.
            code = _stopped(late, "rig", " as it finished; its results are complete")
    except KeyboardInterrupt as interrupt:
        code = _stopped(type(interrupt), "rig", " while starting; nothing was done")
    except SystemExit as exit_:
        code = exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else EXIT_USER_ERROR)
        if exit_.code is not None and not isinstance(exit_.code, int):
            print(exit_.code, file=sys.stderr)
    except Exception:
        late = interrupts.pending()
        if late is not None:
            # A library that turned the interrupt into an error of its own (an extension's import does).
            code = _stopped(late, "rig", "; everything recorded so far is on disk")
        else:
            traceback.print_exc()
            print(f"rig: {REPORT_A_FAULT}", file=sys.stderr)
            code = EXIT_FAULT
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":
    run()
