"""A run of the rig on one clock, against the device protocols: the same session simulated or live.

    Session(parts, t_begin, t_end, record).run()

`rig.session.session` holds the event loop, `rig.session.timing` the renderer's timing policies and
cost models, `rig.session.run_record` the files a run writes as it goes.
"""

from rig.session.run_record import RUN_FILES, RunRecord
from rig.session.session import Session, SessionLog, SessionParts, ShownImage
from rig.session.timing import (
    DEFAULT_SERVER_MS,
    PHOTON_TARGETS,
    CompositeEveryRefresh,
    CostModel,
    MeasuredCost,
    ModelledCost,
    OneImagePerAppFrame,
    PhotonTarget,
    TimingPolicy,
    cost_model,
    timing_for,
)

__all__ = [
    "DEFAULT_SERVER_MS",
    "PHOTON_TARGETS",
    "RUN_FILES",
    "CompositeEveryRefresh",
    "CostModel",
    "MeasuredCost",
    "ModelledCost",
    "OneImagePerAppFrame",
    "PhotonTarget",
    "RunRecord",
    "Session",
    "SessionLog",
    "SessionParts",
    "ShownImage",
    "TimingPolicy",
    "cost_model",
    "timing_for",
]
