"""The renderer registry: built-in names, and third-party renderers found through entry points."""

from __future__ import annotations

import sys
import textwrap

import numpy as np
import pytest

from predictors import Pose
from rig.errors import ConfigError, RigError
from rig.render import AppFrameRequest, Renderer, RenderSetup, make_renderer, renderer_names
from rig.render.direct import DirectRenderer

TINY_RENDERER = '''
import numpy as np

from rig.render.protocol import AppFrameResult


class TinyRenderer:
    """Fills the frame with grey; costs a modelled millisecond."""

    name = "tiny"
    per_display_frame = False

    def open(self, setup):
        self.shape = (setup.height, setup.width, 3)

    def render_app_frame(self, request):
        pose = request.predict(request.t_photon)
        return AppFrameResult(0.001, "modelled", pose, np.full(self.shape, 128, dtype=np.uint8))

    def render_display_frame(self, request):
        raise RuntimeError("tiny shows application frames only")

    def close(self):
        pass
'''


def install(root, distribution: str, module: str, source: str, entry_points: str) -> None:
    """Lay out an installed distribution (module plus dist-info) under `root`, as pip would."""
    (root / f"{module}.py").write_text(textwrap.dedent(source))
    dist_info = root / f"{distribution}-0.1.dist-info"
    dist_info.mkdir()
    (dist_info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {distribution}\nVersion: 0.1\n")
    (dist_info / "entry_points.txt").write_text(f"[rig.renderers]\n{entry_points}\n")


@pytest.fixture
def site(tmp_path, monkeypatch):
    """A fresh directory on sys.path that importlib.metadata scans for distributions."""
    monkeypatch.syspath_prepend(tmp_path)
    yield tmp_path
    for module in ("tiny_renderer", "broken_renderer", "not_a_renderer"):
        sys.modules.pop(module, None)


def test_built_in_renderers_are_listed_and_made():
    assert "direct" in renderer_names()
    renderer = make_renderer("direct")
    assert isinstance(renderer, DirectRenderer)
    assert make_renderer("direct") is not renderer


def test_unknown_name_is_a_config_error_listing_the_names():
    with pytest.raises(ConfigError, match=r"unknown renderer 'nope'.*available renderers: .*direct"):
        make_renderer("nope")


def test_installed_third_party_renderer_is_found_and_renders(site):
    install(site, "tiny-renderer", "tiny_renderer", TINY_RENDERER, "tiny = tiny_renderer:TinyRenderer")
    assert {"direct", "tiny"} <= set(renderer_names())
    renderer = make_renderer("tiny")
    assert type(renderer).__name__ == "TinyRenderer"
    assert isinstance(renderer, Renderer)
    renderer.open(RenderSetup(8, 6, np.eye(4), 0.1))
    pose = Pose(0.25, np.array([0.0, 0.0, -1.0]), np.array([1.0, 0.0, 0.0, 0.0]))
    result = renderer.render_app_frame(AppFrameRequest(0, 0.0, 0.25, lambda t: pose))
    renderer.close()
    assert result.image.shape == (6, 8, 3)
    assert result.pose is pose and result.cost_source == "modelled"


def test_entry_point_that_fails_to_import_is_a_rig_error_naming_its_distribution(site):
    install(site, "broken-renderer", "broken_renderer", "import no_such_module_here\n", "broken = broken_renderer:Broken")
    with pytest.raises(RigError, match=r"'broken'.*broken-renderer 0\.1.*ModuleNotFoundError.*no_such_module_here"):
        make_renderer("broken")


def test_entry_point_to_a_missing_class_is_a_rig_error(site):
    install(site, "tiny-renderer", "tiny_renderer", TINY_RENDERER, "tiny = tiny_renderer:Missing")
    with pytest.raises(RigError, match=r"tiny-renderer 0\.1.*AttributeError.*Missing"):
        make_renderer("tiny")


def test_entry_point_to_something_that_is_not_a_renderer_is_a_rig_error(site):
    install(site, "not-a-renderer", "not_a_renderer", "class Thing:\n    pass\n", "thing = not_a_renderer:Thing")
    with pytest.raises(RigError, match=r"not-a-renderer 0\.1.*does not satisfy"):
        make_renderer("thing")


def test_name_registered_by_two_distributions_is_a_rig_error(site):
    install(site, "tiny-renderer", "tiny_renderer", TINY_RENDERER, "tiny = tiny_renderer:TinyRenderer")
    install(site, "not-a-renderer", "not_a_renderer", "class Thing:\n    pass\n", "tiny = not_a_renderer:Thing")
    with pytest.raises(RigError, match=r"several.*not-a-renderer 0\.1.*tiny-renderer 0\.1|several.*tiny-renderer 0\.1.*not-a-renderer 0\.1"):
        make_renderer("tiny")


def test_built_in_name_wins_over_an_entry_point(site):
    install(site, "tiny-renderer", "tiny_renderer", TINY_RENDERER, "direct = tiny_renderer:TinyRenderer")
    assert renderer_names().count("direct") == 1
    assert isinstance(make_renderer("direct"), DirectRenderer)
