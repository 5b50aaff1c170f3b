"""The session drives whatever stands behind the device protocols: here a scripted tracker, a
renderer without OpenGL and the simulated display, with each timing policy and cost model."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import predictors
from predictors import Pose, PoseSample, read_samples
from rig.clock import VirtualClock
from rig.errors import ConfigError, RigError
from rig.render.protocol import AppFrameResult, DisplayFrameRequest, DisplayFrameResult, RenderSetup
from rig.session import (
    CompositeEveryRefresh,
    MeasuredCost,
    ModelledCost,
    OneImagePerAppFrame,
    PhotonTarget,
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
    """Grey images; each application frame 'takes' 1 ms, each composed image the next of
    `display_costs_s` (the last one repeating), 1 ms if none are given."""

    name = "flat"

    def __init__(self, per_display_frame: bool, display_costs_s: tuple[float, ...] = (0.001,)) -> None:
        self.per_display_frame = per_display_frame
        self.display_costs_s = list(display_costs_s)
        self.requests: list[float] = []
        self.display_requests: list[tuple[DisplayFrameRequest, Pose]] = []

    def open(self, setup: RenderSetup) -> None:
        self.shape = (setup.height, setup.width, 3)

    def render_app_frame(self, request):
        pose = request.predict(request.t_photon)
        self.requests.append(request.t_start)
        image = None if self.per_display_frame else np.full(self.shape, 128, dtype=np.uint8)
        return AppFrameResult(0.001, pose, image)

    def render_display_frame(self, request):
        pose = request.predict(request.t_photon)
        self.display_requests.append((request, pose))
        cost = self.display_costs_s.pop(0) if len(self.display_costs_s) > 1 else self.display_costs_s[0]
        return DisplayFrameResult(np.full(self.shape, 200, dtype=np.uint8), cost, pose)

    def close(self) -> None:
        pass


def run(tmp_path: Path, renderer: FlatRenderer, timing, app_cost, target: PhotonTarget = PhotonTarget()) -> tuple[Session, Path]:
    display = SimDisplay(DisplayConfig(refresh_hz=REFRESH_HZ, t0=0.0))
    parts = SessionParts(
        VirtualClock(0.0), ScriptedTracker(), predictors.make("hold"), renderer, SETUP, timing, app_cost, display, target=target
    )
    with RunRecord(tmp_path) as record:
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
    with RunRecord(tmp_path) as record, pytest.raises(RigError, match="no tracker sample arrived"):
        Session(parts, 0.0, 0.2, record).run()


def new_images(shown: list[dict[str, str]]) -> list[tuple[int, int]]:
    """(refresh, image) of every refresh that showed a new image."""
    return [(int(r["refresh"]), int(r["image"])) for r in shown if r["missed"] == "0"]


def assert_missed_refreshes_repeat_the_last_image(shown: list[dict[str, str]]) -> None:
    for before, row in zip(shown, shown[1:]):
        assert (row["missed"] == "1") == (row["image"] == before["image"])
    assert shown[0]["missed"] == "0"


def newest_sensor_time_at(t: float) -> float:
    """What ScriptedTracker has delivered by `t`: a sample every 5 ms, 2 ms in transit."""
    return np.floor((t - 0.002) / 0.005 + 1e-9) * 0.005


def test_a_server_slower_than_a_refresh_composes_for_the_refreshes_it_can_make_and_the_others_miss(tmp_path) -> None:
    """23 ms a composition at 100 Hz: aimed 23.2 ms (cost and swap margin) before a blank, ready
    0.2 ms before it, then free too late for the next two blanks."""
    renderer = FlatRenderer(per_display_frame=True, display_costs_s=(0.023,))
    session, out = run(tmp_path, renderer, CompositeEveryRefresh(MeasuredCost()), MeasuredCost())
    shown = rows(out / "display_frames.csv")
    fresh = new_images(shown)
    # the first, expected to take a refresh, overran; each later one made the refresh it was aimed at
    assert fresh[0][0] > fresh[0][1] and all(refresh == image for refresh, image in fresh[1:])
    assert np.diff([refresh for refresh, _ in fresh[1:]]).tolist() == [3] * (len(fresh) - 2)
    assert_missed_refreshes_repeat_the_last_image(shown)
    assert sum(r["missed"] == "1" for r in shown) == len(shown) - len(fresh) > len(shown) / 2
    assert {(r["image_cost_s"], r["cost_source"]) for r in shown} == {("0.023", "measured")}
    # from the second composition on, the server started 23.2 ms before its blank and saw only the
    # samples that had arrived by then
    for request, pose in renderer.display_requests[1:]:
        assert pose.position[0] == pytest.approx(newest_sensor_time_at(request.t_vblank - 0.0232))
    assert session.parts.timing.display_frame_cost() == {
        "source": "measured", "frames": len(fresh), "median_ms": 23.0, "p95_ms": 23.0, "max_ms": 23.0,
    }  # fmt: skip


def test_a_composition_that_overruns_its_blank_misses_it_and_a_lone_stall_does_not_move_the_plan(tmp_path) -> None:
    """3 ms compositions, one of 9 ms: it appears a refresh late, the refresh it was aimed at repeats
    the previous image, and the next composition still plans for 3 ms."""
    costs = (0.003,) * 6 + (0.009,) + (0.003,)
    renderer = FlatRenderer(per_display_frame=True, display_costs_s=costs)
    _, out = run(tmp_path, renderer, CompositeEveryRefresh(MeasuredCost()), MeasuredCost())
    shown = rows(out / "display_frames.csv")
    assert_missed_refreshes_repeat_the_last_image(shown)
    missed = [int(r["refresh"]) for r in shown if r["missed"] == "1"]
    spike_request, _ = renderer.display_requests[6]
    assert missed == [spike_request.index]
    late = next(r for r in shown if r["image"] == str(spike_request.index))
    assert int(late["refresh"]) == spike_request.index + 1 and late["image_cost_s"] == "0.009"
    after, pose = renderer.display_requests[7]
    assert after.index == spike_request.index + 2
    assert pose.position[0] == pytest.approx(newest_sensor_time_at(after.t_vblank - 0.003 - 0.0002))


def test_a_server_that_plans_for_more_than_a_refresh_and_takes_less_keeps_composing(tmp_path) -> None:
    """Steady 25 ms compositions at 100 Hz, then 2 ms ones: a plan longer than a refresh starts
    compositions before the refresh in front of the one they aim at. Each image must still appear
    no earlier than a refresh the display has not shown yet, and the server must go on composing
    as the plan comes down (a display that placed an image on a refresh already shown once froze
    the server here)."""
    costs = (0.025,) * 8 + (0.002,) * 40
    renderer = FlatRenderer(per_display_frame=True, display_costs_s=costs)
    display = SimDisplay(DisplayConfig(refresh_hz=REFRESH_HZ, t0=0.0))
    parts = SessionParts(VirtualClock(0.0), ScriptedTracker(), predictors.make("hold"), renderer, SETUP,
                         CompositeEveryRefresh(MeasuredCost()), MeasuredCost(), display)  # fmt: skip
    with RunRecord(tmp_path) as record:
        Session(parts, 0.0, 0.6, record).run()
    shown = rows(tmp_path / "display_frames.csv")
    assert_missed_refreshes_repeat_the_last_image(shown)
    fresh = new_images(shown)
    assert all(refresh >= image for refresh, image in fresh)
    # once the 2 ms costs outnumber the 25 ms ones in the plan's window, every refresh shows a new image
    assert [refresh for refresh, _ in fresh][-10:] == [int(r["refresh"]) for r in shown][-10:]
def test_a_direct_renderer_that_overruns_a_refresh_leaves_the_display_repeating_its_last_frame(tmp_path) -> None:
    renderer = FlatRenderer(per_display_frame=False)
    _, out = run(tmp_path, renderer, OneImagePerAppFrame(), ModelledCost(25.0))
    shown = rows(out / "display_frames.csv")
    assert_missed_refreshes_repeat_the_last_image(shown)
    assert [refresh for refresh, _ in new_images(shown)] == list(range(3, 21, 3))
    assert {(r["image_cost_s"], r["cost_source"]) for r in shown} == {("0.025", "modelled")}


@pytest.mark.parametrize(("target", "after_blank_s"), [(PhotonTarget("scanout"), 0.005), (PhotonTarget(), 0.010), (PhotonTarget("photons", 0.2), 0.006)])
def test_frames_are_predicted_for_the_photon_target_at_the_spheres_row(tmp_path, target, after_blank_s) -> None:
    """The sphere's row is the middle (scan-out 5 ms after the blank at 100 Hz); a row emits for the
    persistence's share of the 10 ms refresh."""
    renderer = FlatRenderer(per_display_frame=True)
    for folder in ("composed", "direct"):
        (tmp_path / folder).mkdir()
    run(tmp_path / "composed", renderer, CompositeEveryRefresh(ModelledCost(2.0)), MeasuredCost(), target)
    for request, _ in renderer.display_requests:
        assert request.t_photon == pytest.approx(request.t_vblank + after_blank_s)
    _, out = run(tmp_path / "direct", FlatRenderer(per_display_frame=False), OneImagePerAppFrame(), ModelledCost(3.0), target)
    apps, shown = rows(out / "app_frames.csv"), rows(out / "display_frames.csv")
    for app, row in zip(apps, shown):
        assert float(app["t_photon_target"]) == pytest.approx(float(row["t_vblank"]) + after_blank_s)


def test_a_photon_target_is_checked() -> None:
    with pytest.raises(ConfigError, match="photons, scanout"):
        PhotonTarget("vblank")
    for persistence in (0.0, 1.5, float("nan")):
        with pytest.raises(ConfigError, match="persistence"):
            PhotonTarget("photons", persistence)


def test_after_an_overrun_the_server_aims_past_the_refresh_its_late_image_took(tmp_path) -> None:
    """3 ms compositions, one of 4 ms that overruns its blank by 0.8 ms: it appears a refresh late,
    and the next composition aims at the refresh after that. Aimed at the refresh the late image
    took, it would queue behind it, and every image from then on would appear a refresh late."""
    costs = (0.003,) * 6 + (0.004,) + (0.003,)
    renderer = FlatRenderer(per_display_frame=True, display_costs_s=costs)
    _, out = run(tmp_path, renderer, CompositeEveryRefresh(MeasuredCost()), MeasuredCost())
    shown = rows(out / "display_frames.csv")
    assert_missed_refreshes_repeat_the_last_image(shown)
    spike_request, _ = renderer.display_requests[6]
    late = next(r for r in shown if r["image"] == str(spike_request.index))
    assert int(late["refresh"]) == spike_request.index + 1
    assert renderer.display_requests[7][0].index == spike_request.index + 2
    fresh = new_images(shown)
    assert [refresh for refresh, image in fresh if refresh != image] == [spike_request.index + 1]
    assert [int(r["refresh"]) for r in shown if r["missed"] == "1"] == [spike_request.index]
