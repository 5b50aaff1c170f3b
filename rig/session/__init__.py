"""A run of the rig on one clock, against the device protocols: the same session simulated or live.

    Session(parts, t_begin, t_end, record).run()

`rig.session.session` holds the event loop, `rig.session.timing` the renderer's timing policies and
cost models, `rig.session.run_record` the files a run writes as it goes.
"""

from declared.lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "RUN_FILES": "rig.session.run_files",
        "RunRecord": "rig.session.run_record",
        "Session": "rig.session.session",
        "SessionLog": "rig.session.session",
        "SessionParts": "rig.session.session",
        "ShownImage": "rig.session.session",
        "DEFAULT_SERVER_MS": "rig.session.photon_target",
        "PHOTON_TARGETS": "rig.session.photon_target",
        "CompositeEveryRefresh": "rig.session.timing",
        "CostModel": "rig.session.timing",
        "MeasuredCost": "rig.session.timing",
        "ModelledCost": "rig.session.timing",
        "OneImagePerAppFrame": "rig.session.timing",
        "PhotonTarget": "rig.session.photon_target",
        "TimingPolicy": "rig.session.timing",
        "cost_model": "rig.session.timing",
        "timing_for": "rig.session.timing",
    },
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
