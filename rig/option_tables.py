"""The docs' tables of options and settings (docs/options.md), made from their declarations:
`python -m rig.option_tables > docs/options.md` after changing a declaration (a test checks the
file is current)."""

from __future__ import annotations

from analysis import AnalysisOptions
from analysis.shutter import ShutterOptions
from declared.docs import markdown_table
from rig.bench.batch_settings import BatchBenchOptions
from rig.bench.predictors_settings import PredictorBenchOptions
from rig.bench.renderer_specs import BenchGrid
from rig.bench.trackers_settings import TrackerBenchOptions
from rig.board.settings import BoardSettings
from rig.commands.board import BlinkOptions, SyncOptions
from rig.commands.devices import Listing
from rig.commands.emulate import EmulatorOptions
from rig.emulator_settings import ReaderWait
from rig.live.config import LiveConfig
from rig.tune_settings import TuneSettings
from rig.service.bench_profile import BenchProfile
from rig.service.plan import PlanRequest
from rig.sim.config import SimulationConfig

SECTIONS = (
    ("Analysis", AnalysisOptions, True, "`rig analyse`'s options, and a sweep's `[analysis]` table by the setting's name."),
    (
        "The simulated rig",
        SimulationConfig,
        True,
        "`rig simulate`'s and `rig demo`'s options (and `--predictor NAME[:key=value,...]`, the predictor with its "
        "parameters, `predictor_params` in a spec; `rig simulate --board`, the simulated board with the defaults "
        "below; `rig simulate --flash-hz F [--flash-duty D]` or `--flash-display N`, the calibration target `flash` "
        "with the defaults below), and a sweep's `[base]`, `[grid]` and `[[points]]` keys.",
    ),
    ("Calibrating a camera", ShutterOptions, True, "`rig calibrate-camera`'s options (with `--flash-hz F`, which every film needs)."),
    (
        "The bench profile",
        BenchProfile,
        False,
        "The keys of a bench profile's `[camera]`, `[display]` and `[layout]` tables: `rig plan --bench` and `rig "
        "calibrate-camera --bench` write it, `rig analyse --bench`, `rig measure --bench` and a sweep's `[analysis] "
        "bench` read it, each value a hint checked against the video.",
    ),
    (
        "The renderer bench's grid",
        BenchGrid,
        False,
        "`rig bench renderers --spec FILE.toml` (its `--triangles`, `--resolutions`, `--ratios`, `--warp`, `--server-ms`, "
        "`--predictor` and `--direct-predictor` override the file).",
    ),
    ("Tuning a predictor", TuneSettings, True, "`rig tune`'s numeric options."),
    ("The predictor bench", PredictorBenchOptions, True, "`rig bench predictors`'s numeric options."),
    ("The tracker bench", TrackerBenchOptions, True, "`rig bench trackers`'s options."),
    ("The batch bench", BatchBenchOptions, True, "`rig bench batch`'s options; a batch that would take more than a day is refused with its estimate."),
    ("The tracker emulator", EmulatorOptions, True, "`rig emulate-tracker`'s numeric options (`--drift-ppm`: `serial` only)."),
    ("The tracker emulator's wait for a reader", ReaderWait, True, "`rig emulate-tracker --idle-timeout`."),
    (
        "A live run",
        LiveConfig,
        True,
        "`rig measure`'s options (and `--predictor NAME[:key=value,...]`, the predictor with its parameters; "
        "`--display`, the window and its scan-out; `--no-lsl`, no streams; `--duration S`, `duration_s`, 20 s with "
        "`--self-test`); `rig record`, `rig record-tracker` and `rig board record` take the same range for their "
        "`--duration`.",
    ),
    ("Planning", PlanRequest, True, "`rig plan --accuracy-ms`."),
    ("Listing devices", Listing, True, "`rig devices`'s options."),
    ("Recording the board", BoardSettings, True, "`rig board record`'s options (the board's own limits are checked when it connects)."),
    ("Synchronising with the board", SyncOptions, True, "`rig board sync`'s options; a series longer than a day is refused with its estimate."),
    ("The board's blink code", BlinkOptions, True, "`rig board blink`'s and `rig board record --blink`'s options."),
)


def options_markdown() -> str:
    """docs/options.md: a table per declaring config (its options too, where a command's are made from it)."""
    parts = [
        "# Options and settings\n",
        "Made from the declarations by `python -m rig.option_tables > docs/options.md`; do not edit by hand. A "
        "setting is a key of a spec (TOML; nested ones dotted, or as tables), an option is the command line's, "
        "in the unit shown where it differs from the setting's.\n",
    ]
    for title, kind, options, used in SECTIONS:
        parts += [f"## {title} (`{kind.__module__}.{kind.__name__}`)\n", f"{used}\n", markdown_table(kind, options)]
    return "\n".join(parts)


if __name__ == "__main__":
    print(options_markdown(), end="")
