"""The choices the command line offers (predictors, renderers, estimators, trackers), each with a
line saying what it is, for the commands' --help.

The lines are declared here, the first sentence of each class's docstring (a test keeps them so),
because the help lists them without importing the classes: numpy, OpenGL and JAX are behind them.
"""

from __future__ import annotations

from rig.commands.options import choices_listing, first_sentence

TRACKER_SPECS = {
    "serial:URL[?profile=NAME&baud=N]": "a serial tracker: a /dev/tty path, socket://HOST:PORT, rfc2217://HOST:PORT or loop://, "
    "its records in a shipped profile's format or a .toml file's",
    "hid:VID:PID[:PROFILE]": "a USB HID tracker by vendor and product id (`rig devices` lists them)",
    "lsl:NAME": "an LSL pose stream by name",
}
PREDICTOR_LINES = {
    "hold": "No prediction: every answer is the newest sample's pose, stamped with the asked time",
    "slerp": "Linear prediction from the two newest samples (Smit et al. 2010, section 3.2)",
    "kalman-cv": "Kalman filter, constant velocity in position and orientation (`kalman-cv`)",
    "kalman-ca": "Kalman filter, constant acceleration in position, constant angular velocity (`kalman-ca`)",
    "desp": "LaViola's double exponential smoothing predictor (`desp`)",
    "auto": "Chooses per scene between no prediction, constant velocity and constant acceleration for position, and "
    "whether to filter orientation at all (`auto`)",
    "adaptive": "Trusts, per horizon, the candidate model whose realised errors on this stream have been smallest "
    "(`adaptive`); see `predictors.adaptive`",
    "split": "Position from `adaptive`, orientation from `kalman-cv`'s filter with a damped angular velocity (`split`)",
    "rls": "Orientation from coefficients on the angular velocity and its moving averages learnt per horizon on the "
    "stream, position from `adaptive` (`rls`, the default predictor); see `predictors.rls`",
}
"""Each predictor (`predictors.names()`), in the registry's order."""
DEFAULT_PREDICTOR = ("default", "rls")
"""The name that stands for the default predictor, and the predictor it is (`predictors.resolve`)."""
TUNABLE = ("kalman-cv", "kalman-ca", "desp", "auto")
"""The predictors `rig tune` fits (`predictors.tuning.TUNABLE`)."""
RENDERER_LINES = {
    "direct": "Draws a bright sphere at the predicted position in front of dim load geometry",
    "warp": "Client-server depth-image warping; see the module docstring and `WarpOptions` for the options",
}
"""Each built-in renderer (`rig.render.registry.BUILT_IN_RENDERERS`); installed ones are found as entry points."""
METHOD_LINES = {
    "fft": "The phase difference of both signals at the swing frequency, over the angular frequency",
    "xcorr": "The lag of the cross-correlation peak nearest the chosen latency",
    "sinefit": "The lag of the joint fit, with its 95 % interval, in the model chosen by BIC",
    "bayes": "The posterior median and central 95 % interval of the lag, in the model sinefit chose",
}
"""Each built-in estimator (`analysis.methods()`), in the order they run; a lab's own, registered in
this process, is listed by its docstring."""


def predictors_listing() -> str:
    """Every predictor, a line each."""
    default, default_is = DEFAULT_PREDICTOR
    lines = {**PREDICTOR_LINES, default: f"the one used when none is named: {default_is}"}
    return choices_listing("predictors (NAME[:key=value,...] or NAME:FILE.json)", lines)


def renderers_listing() -> str:
    """Every renderer, built-in and installed, a line each."""
    from rig.plugins import RENDERER_GROUP, plugin_names  # reads the installed packages' entry points

    installed = "installed plugin (rig.renderers entry point)"
    lines = {name: RENDERER_LINES.get(name, installed) for name in plugin_names(RENDERER_GROUP, RENDERER_LINES)}
    return choices_listing("renderers (NAME[:key=value,...])", lines)


def trackers_listing() -> str:
    """The tracker specs, a line each."""
    return choices_listing("trackers (SPEC)", TRACKER_SPECS)


def methods_listing() -> str:
    """Every latency estimator `rig analyse --method` takes, a line each."""
    from analysis.estimators.registry import ALL, estimators_for, methods

    lines = {name: METHOD_LINES.get(name) or first_sentence(type(estimators_for(name)[0])) for name in methods()}
    lines[ALL] = "every method above; the result is the default method's, the others printed beside it"
    return choices_listing("methods", lines)


def tunable_listing() -> str:
    """The predictors `rig tune` fits, a line each."""
    return choices_listing("tunable predictors", {name: PREDICTOR_LINES[name] for name in TUNABLE})
