"""The session drives whatever stands behind the device protocols: here a scripted tracker, a
renderer without OpenGL and the simulated display, with each timing policy and cost model."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import predictors
from predictors import PoseSample, read_samples
from rig.clock import VirtualClock
from rig.errors import ConfigError, RigError
from rig.render.protocol import AppFrameResult, DisplayFrameResult, RenderSetup
from rig.session import (
    CompositeEveryRefresh,
    MeasuredCost,
    ModelledCost,
    OneImagePerAppFrame,
    RunRecord,
    Session,
    SessionParts,
    cost_model,
)
from rig.sim.display import DisplayConfig, SimDisplay

REFRESH_HZ = 100.0
SETUP = RenderSetup(16, 16, np.eye(4), 0.1)


class ScriptedTracker:
    """A sample every 5 ms of sensor time, arriving 2 ms later, at x = sensor time."""

    def __init__(self) -> None:
        self.clock: VirtualClock | None = None
        self.sent = 0

    def _arrival(self, k: int) -> float:
        return k * 0.005 + 0.002

    def connect(self, clock: VirtualClock) -> None:
        self.clock = clock

    def poll(self) -> list[PoseSample]:
        samples = []
        while self._arrival(self.sent) <= self.clock.now():
            t = self.sent * 0.005
            samples.append(PoseSample(t, self._arrival(self.sent), np.array([t, 0.0, 0.0]), np.array([1.0, 0.0, 0.0, 0.0])))
            self.sent += 1
        return samples

    def wait(self, timeout_s: float) -> list[PoseSample]:
        self.clock.wait_until(min(self.clock.now() + timeout_s, self._arrival(self.sent)))
        return self.poll()

    def close(self) -> None:
        self.clock = None


class FlatRenderer:
    """Grey images; each piece of work 'takes' 1 ms."""

    name = "flat"

    def __init__(self, per_display_frame: bool) -> None:
        self.per_display_frame = per_display_frame
        self.requests: list[float] = []

    def open(self, setup: RenderSetup) -> None:
        self.shape = (setup.height, setup.width, 3)

    def render_app_frame(self, request):
        pose = request.predict(request.t_photon)
        self.requests.append(request.t_start)
        image = None if self.per_display_frame else np.full(self.shape, 128, dtype=np.uint8)
        return AppFrameResult(0.001, pose, image)

    def render_display_frame(self, request):
        return DisplayFrameResult(np.full(self.shape, 200, dtype=np.uint8), 0.001, request.predict(request.t_photon))

    def close(self) -> None:
        pass


def run(tmp_path: Path, renderer: FlatRenderer, timing, app_cost) -> tuple[Session, Path]:
    display = SimDisplay(DisplayConfig(refresh_hz=REFRESH_HZ, t0=0.0))
    parts = SessionParts(VirtualClock(0.0), ScriptedTracker(), predictors.make("hold"), renderer, SETUP, timing, app_cost, display)
    with RunRecord(tmp_path, None) as record:
        session = Session(parts, 0.0, 0.2, record)
        session.run()
    return session, tmp_path


def rows(path: Path) -> list[dict[str, str]]:
    with path.open() as stream:
        return list(csv.DictReader(stream))


def test_a_direct_renderer_shows_each_frame_at_the_next_blank_and_starts_the_next_there(tmp_path) -> None:
    renderer = FlatRenderer(per_display_frame=False)
    session, out = run(tmp_path, renderer, OneImagePerAppFrame(), ModelledCost(3.0))
    apps = rows(out / "app_frames.csv")
    assert [float(a["t_start"]) for a in apps] == pytest.approx([0.002] + [k / REFRESH_HZ for k in range(1, 21)])
    assert {a["cost_source"] for a in apps} == {"modelled"}
    assert all(float(a["cost_s"]) == 0.003 for a in apps)
    shown = rows(out / "display_frames.csv")
    assert [int(r["image"]) for r in shown] == list(range(len(shown)))
    assert [int(r["refresh"]) for r in shown] == list(range(1, len(shown) + 1))
    samples = read_samples(out / "tracker.csv")
    assert [s.t_sensor for s in samples] == pytest.approx([k * 0.005 for k in range(len(samples))])
    assert samples[-1].t_arrival <= 0.2


def test_a_compositing_renderer_draws_every_refresh_from_its_server_start(tmp_path) -> None:
    renderer = FlatRenderer(per_display_frame=True)
    session, out = run(tmp_path, renderer, CompositeEveryRefresh(ModelledCost(2.0)), MeasuredCost())
    apps = rows(out / "app_frames.csv")
    assert {a["cost_source"] for a in apps} == {"measured"}
    np.testing.assert_allclose(np.diff([float(a["t_start"]) for a in apps]), 0.001)
    shown = rows(out / "display_frames.csv")
    assert [int(r["image"]) for r in shown] == [int(r["refresh"]) for r in shown]
    assert int(shown[0]["refresh"]) == 1
    # the server samples 2 ms before each blank: the newest sample is at least that old at the blank
    ages = [float(r["t_vblank"]) - float(r["t_sensor_newest"]) for r in shown]
    assert min(ages) >= 0.002 + 0.002 - 1e-12


def test_costs_are_charged_as_modelled_or_as_measured() -> None:
    assert ModelledCost(12.5).charge(0.3) == 0.0125 and ModelledCost(12.5).source == "modelled"
    assert MeasuredCost().charge(0.3) == 0.3 and MeasuredCost().source == "measured"
    assert ModelledCost(12.5).expected_s(0.01) == 0.0125 and MeasuredCost().expected_s(0.01) == 0.01
    assert cost_model(None) == MeasuredCost() and cost_model(4.0) == ModelledCost(4.0)
    with pytest.raises(ConfigError, match="positive number of ms"):
        ModelledCost(-2.0)


def test_a_tracker_that_never_sends_is_reported(tmp_path) -> None:
    class Silent(ScriptedTracker):
        def _arrival(self, k: int) -> float:
            return 10.0

    display = SimDisplay(DisplayConfig(refresh_hz=REFRESH_HZ))
    parts = SessionParts(VirtualClock(0.0), Silent(), predictors.make("hold"), FlatRenderer(False), SETUP,
                         OneImagePerAppFrame(), ModelledCost(3.0), display)  # fmt: skip
    with RunRecord(tmp_path, None) as record, pytest.raises(RigError, match="no tracker sample arrived"):
        Session(parts, 0.0, 0.2, record).run()
