"""The choices the command line offers (predictors, renderers, estimators, trackers), each with a
line saying what it is, for the commands' --help."""

from __future__ import annotations

from rig.commands.options import choices_listing, first_sentence

TRACKER_SPECS = {
    "serial:URL[?profile=NAME&baud=N]": "a serial tracker: a /dev/tty path, socket://HOST:PORT, rfc2217://HOST:PORT or loop://, "
    "its records in a shipped profile's format or a .toml file's",
    "hid:VID:PID[:PROFILE]": "a USB HID tracker by vendor and product id (`rig devices` lists them)",
    "lsl:NAME": "an LSL pose stream by name",
}


def predictors_listing() -> str:
    """Every predictor, a line each."""
    import predictors

    lines = {name: first_sentence(type(predictors.make(name))) for name in predictors.names()}
    lines[predictors.DEFAULT] = f"the one used when none is named: {predictors.resolve(predictors.DEFAULT)}"
    return choices_listing("predictors (NAME[:key=value,...] or NAME:FILE.json)", lines)


def renderers_listing() -> str:
    """Every renderer, built-in and installed, a line each."""
    from rig.render import renderer_names
    from rig.render.registry import BUILT_IN_RENDERERS

    lines = {
        name: first_sentence(BUILT_IN_RENDERERS[name]) if name in BUILT_IN_RENDERERS else "installed plugin (rig.renderers entry point)"
        for name in renderer_names()
    }
    return choices_listing("renderers (NAME[:key=value,...])", lines)


def trackers_listing() -> str:
    """The tracker specs, a line each."""
    return choices_listing("trackers (SPEC)", TRACKER_SPECS)


def methods_listing() -> str:
    """Every latency estimator `rig analyse --method` takes, a line each."""
    import analysis
    from analysis.estimators.registry import ALL, estimators_for

    lines = {name: first_sentence(type(estimators_for(name)[0])) for name in analysis.methods()}
    lines[ALL] = "every method above; the result is the default method's, the others printed beside it"
    return choices_listing("methods", lines)


def tunable_listing() -> str:
    """The predictors `rig tune` fits, a line each."""
    import predictors
    from predictors.tuning import TUNABLE

    return choices_listing("tunable predictors", {name: first_sentence(type(predictors.make(name))) for name in TUNABLE})
