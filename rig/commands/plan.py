"""`rig plan`: which camera setting, film length and layout measure the latency to the accuracy wanted.

Simulates every camera rate and exposure on offer filming the display (`rig.service.plan`), prints
each one's expected 95 % half-width and sampling bias bound, and recommends one, checked by a
simulation, with the `rig simulate` and `rig analyse` lines that film and measure it. Exit status
0 with a recommendation, 1 when no setting on offer reaches the accuracy, 2 for bad options.
"""

from __future__ import annotations

import argparse
import json
from datetime import date
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rig.commands import options, outputs
from rig.commands.declared_options import add_declared_option
from rig.plan_settings import PlanAccuracy
from rig.sim.display_config import DisplayConfig
from rig.sim.pendulum_config import PendulumConfig

if TYPE_CHECKING:
    from rig.service import Plan

EXIT_UNREACHABLE = 1


def _numbers(text: str) -> tuple[float, ...]:
    """A comma-separated list of positive numbers."""
    return tuple(options.positive_float(part) for part in text.split(","))


def _print(result: Plan) -> None:
    request = result.request
    print(
        f"filming a {request.display_hz:g} Hz display, a {request.period_s:g} s pendulum swinging "
        f"{request.amplitude_deg:g} degrees, for a 95% half-width of {request.accuracy_ms:g} ms:"
    )
    print("| camera fps | exposure | phases per refresh | bias if phase-locked | half-width (trial) | film for the accuracy |")
    print("| --- | --- | --- | --- | --- | --- |")
    for s in result.settings:
        film = f"{s.film_s:g} s" if s.film_s is not None else "not reached"
        phases = "all (walk)" if s.phases is None else str(s.phases)
        print(
            f"| {s.camera_fps:g} | {s.exposure:.0%} ({s.exposure_ms:.3g} ms) | {phases} | +-{s.bias_bound_ms:.2f} ms | "
            f"{s.statistical_ms + s.added_ms:.3f} ms over {s.trial_s:g} s | {film} |"
        )
    best = result.recommended
    if best is None:
        print(f"no setting on offer reaches {request.accuracy_ms:g} ms: offer a faster camera, or expose for whole refreshes")
        return
    checked = result.checked or {}
    print(
        f"recommended: {best.camera_fps:g} fps exposing {best.exposure:.0%} of each frame ({best.exposure_ms:.3g} ms), "
        f"{best.film_s:g} s of film; checked by simulation: 95% half-width {checked.get('half_width_ms', 0.0):.3f} ms, "
        f"error {checked.get('error_ms', 0.0):+.3f} ms"
    )
    print(f"layout: {result.layout['advice']}; LED region {result.layout['led_roi']}, sphere region {result.layout['sphere_roi']}")
    for line in result.commands():
        print(f"  {line}")


def _run(args: argparse.Namespace) -> int:
    from rig.bench.contract import log_to_stderr
    from rig.service import PlanRequest, plan
    from rig.service.bench_profile import BenchProfile, read_profile, write_profile

    request = PlanRequest(
        display_hz=args.display_hz,
        camera_fps=args.camera_fps,
        exposures=args.exposures,
        period_s=args.period_s,
        amplitude_deg=args.amplitude_deg,
        accuracy_ms=args.accuracy_ms,
    )
    current = read_profile(args.bench) if args.bench is not None and args.bench.exists() else BenchProfile()
    result = plan(request, log_to_stderr, args.runs)
    if args.json:
        print(json.dumps(result.to_dict()))
    else:
        _print(result)
    if args.bench is not None:
        changes = result.bench_changes(current.camera, date.today().isoformat())
        write_profile(args.bench, changes)
        (log_to_stderr if args.json else print)(profile_line(args.bench, changes))
    return 0 if result.recommended is not None else EXIT_UNREACHABLE


def profile_line(path: Path, changes: dict[str, dict[str, Any]]) -> str:
    """What the plan wrote into the bench profile."""
    camera = changes.get("camera")
    written = f"the display's {changes['display']['refresh_hz']:g} Hz"
    if camera is not None:
        written += f" and the camera's {camera['fps']:g} fps exposing {camera['exposure_ms']:.4g} ms"
    removed = " (its readout, for another frame rate, removed: calibrate the camera at this setting)" if camera and "readout_ms" in camera else ""
    return f"bench profile {path}: wrote {written}{removed}"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "plan",
        description="Simulate each camera frame rate and exposure on offer filming the display, analyse each as a "
        "lab would (the settings given), and recommend the one that reaches the wanted 95 % half-width with the "
        "shortest film, checked by a simulation; print every setting's expected half-width and the bias a "
        "phase-locked camera could have. Exit status 0 with a recommendation, 1 when none reaches the accuracy.",
    )
    add_declared_option(parser, DisplayConfig, "refresh_hz", required=True)
    parser.add_argument(
        "--camera-fps", type=_numbers, required=True, metavar="F,F,...", help="the camera's frame rates on offer (20-2000)"
    )
    parser.add_argument(
        "--exposures",
        type=_numbers,
        default=(1.0,),
        metavar="E,E,...",
        help="exposures on offer, as fractions of the frame interval in (0, 1] (default: 1, the whole interval)",
    )
    add_declared_option(parser, PendulumConfig, "period_s")
    add_declared_option(parser, PendulumConfig, "amplitude_deg")
    add_declared_option(parser, PlanAccuracy, "accuracy_ms")
    parser.add_argument("--runs", type=outputs.output_folder, metavar="DIR", help="keep the simulated films here (default: a temporary folder)")
    parser.add_argument(
        "--bench",
        type=outputs.output_file(".toml"),
        metavar="FILE.toml",
        help="write the display and the recommended camera setting into this bench profile (made if there is none; "
        "what else it holds is kept), which rig analyse --bench reads",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=_run)
