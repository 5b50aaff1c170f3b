"""Devices by spec: the simulated twins inside a simulated run, and a third party's device added with
one module and one entry point, from outside the rig."""

from __future__ import annotations

import numpy as np
import pytest

from rig.clock import VirtualClock
from rig.devices.protocols import Camera, Display, TrackerSource
from rig.devices.registry import DeviceContext, make_camera, make_display, make_tracker
from rig.errors import ConfigError, RigError
from rig.sim.config import SimulationConfig
from rig.sim.world import SimulatedWorld

DUMMY_TRACKER = '''
import numpy as np

from predictors import PoseSample


class DummyTracker:
    """A sample every 10 ms from 0 s, arriving 2 ms later, at x = the address in metres."""

    def __init__(self, address, context):
        self.x = float(address)
        self.clock = None
        self.sent = 0

    def connect(self, clock):
        self.clock = clock

    def poll(self):
        samples = []
        while self.sent * 0.01 + 0.002 <= self.clock.now():
            t = self.sent * 0.01
            samples.append(PoseSample(t, t + 0.002, np.array([self.x, 0.0, 0.0]), np.array([1.0, 0.0, 0.0, 0.0])))
            self.sent += 1
        return samples

    def wait(self, timeout_s):
        self.clock.wait_until(min(self.clock.now() + timeout_s, self.sent * 0.01 + 0.002))
        return self.poll()

    def fault(self):
        return None

    def report(self):
        return {"tracker": "dummy", "sent": self.sent}

    def close(self):
        self.clock = None
'''


def test_a_simulated_run_passes_the_twin_of_every_kind_it_makes() -> None:
    world = SimulatedWorld(SimulationConfig(duration_s=1.0))
    context = DeviceContext(world.twins())
    assert isinstance(make_tracker("sim", context), TrackerSource)
    display = make_display("sim", context)
    assert isinstance(display, Display) and display is world.display()
    camera = make_camera("sim", context)
    assert isinstance(camera, Camera) and camera is world.camera()
    assert camera.scene.display is display


def test_the_simulated_twins_exist_only_inside_a_simulation() -> None:
    with pytest.raises(ConfigError, match="only in a simulated run"):
        make_tracker("sim")
    with pytest.raises(ConfigError, match="takes no address"):
        make_camera("sim:0")


def test_an_unknown_scheme_is_a_config_error_listing_the_schemes() -> None:
    with pytest.raises(ConfigError, match=r"unknown tracker 'polhemus'.*available trackers: .*sim"):
        make_tracker("polhemus:/dev/ttyUSB0")


def test_a_third_party_tracker_is_one_module_and_one_entry_point(site) -> None:
    site.install("dummy-tracker", "dummy_tracker", DUMMY_TRACKER, "rig.trackers", "dummy = dummy_tracker:DummyTracker")
    with pytest.raises(ConfigError, match=r"available trackers: .*dummy.*sim"):
        make_tracker("polhemus:/dev/ttyUSB0")
    tracker = make_tracker("dummy:0.25")
    assert isinstance(tracker, TrackerSource)
    clock = VirtualClock()
    tracker.connect(clock)
    first = tracker.wait(1.0)
    assert clock.now() == pytest.approx(0.002)
    clock.wait_until(0.035)
    later = tracker.poll()
    tracker.close()
    assert [s.t_sensor for s in first + later] == pytest.approx([0.0, 0.01, 0.02, 0.03])
    assert tracker.report() == {"tracker": "dummy", "sent": 4}
    assert all(s.position[0] == 0.25 for s in first + later)


def test_an_entry_point_that_is_not_a_tracker_is_a_rig_error_naming_its_distribution(site) -> None:
    site.install("not-a-tracker", "not_a_tracker", "class Thing:\n    def __init__(self, a, c):\n        pass\n",
            "rig.trackers", "thing = not_a_tracker:Thing")  # fmt: skip
    with pytest.raises(RigError, match=r"not-a-tracker 0\.1.*TrackerSource"):
        make_tracker("thing")


def test_a_tracker_without_a_report_does_not_satisfy_the_protocol(site) -> None:
    silent = DUMMY_TRACKER.replace("    def report(self):", "    def _report(self):")
    site.install("silent-tracker", "silent_tracker", silent, "rig.trackers", "silent = silent_tracker:DummyTracker")
    with pytest.raises(RigError, match=r"silent-tracker 0\.1.*does not satisfy the TrackerSource protocol"):
        make_tracker("silent:0.25")
