"""The renderer registry: built-in names, and third-party renderers found through entry points."""

from __future__ import annotations

import numpy as np
import pytest

from predictors import Pose
from rig.errors import ConfigError, RigError
from rig.render import AppFrameRequest, Renderer, RenderSetup, make_renderer, renderer_names
from rig.render.direct import DirectRenderer
from rig.render.warp import WarpRenderer
from rig.render.warp_options import WarpOptions

TINY_RENDERER = '''
import numpy as np

from rig.render.protocol import AppFrameResult


class TinyRenderer:
    """Fills the frame with grey in a millisecond."""

    name = "tiny"
    per_display_frame = False

    def open(self, setup):
        self.shape = (setup.height, setup.width, 3)

    def render_app_frame(self, request):
        pose = request.predict(request.t_photon)
        return AppFrameResult(0.001, pose, np.full(self.shape, 128, dtype=np.uint8))

    def render_display_frame(self, request):
        raise RuntimeError("tiny shows application frames only")

    def close(self):
        pass
'''


def test_built_in_renderers_are_listed_and_made():
    assert "direct" in renderer_names()
    renderer = make_renderer("direct")
    assert isinstance(renderer, DirectRenderer)
    assert make_renderer("direct") is not renderer


def test_unknown_name_is_a_config_error_listing_the_names():
    with pytest.raises(ConfigError, match=r"unknown renderer 'nope'.*available renderers: .*direct"):
        make_renderer("nope")


def test_installed_third_party_renderer_is_found_and_renders(site):
    site.install("tiny-renderer", "tiny_renderer", TINY_RENDERER, "rig.renderers", "tiny = tiny_renderer:TinyRenderer")
    assert {"direct", "tiny"} <= set(renderer_names())
    renderer = make_renderer("tiny")
    assert type(renderer).__name__ == "TinyRenderer"
    assert isinstance(renderer, Renderer)
    renderer.open(RenderSetup(8, 6, np.eye(4), 0.1))
    pose = Pose(0.25, np.array([0.0, 0.0, -1.0]), np.array([1.0, 0.0, 0.0, 0.0]))
    result = renderer.render_app_frame(AppFrameRequest(0, 0.0, 0.25, lambda t: pose))
    renderer.close()
    assert result.image.shape == (6, 8, 3)
    assert result.pose is pose and result.cost_s == 0.001


def test_entry_point_that_fails_to_import_is_a_rig_error_naming_its_distribution(site):
    site.install("broken-renderer", "broken_renderer", "import no_such_module_here\n", "rig.renderers", "broken = broken_renderer:Broken")
    with pytest.raises(RigError, match=r"'broken'.*broken-renderer 0\.1.*ModuleNotFoundError.*no_such_module_here"):
        make_renderer("broken")


def test_entry_point_to_a_missing_class_is_a_rig_error(site):
    site.install("tiny-renderer", "tiny_renderer", TINY_RENDERER, "rig.renderers", "tiny = tiny_renderer:Missing")
    with pytest.raises(RigError, match=r"tiny-renderer 0\.1.*AttributeError.*Missing"):
        make_renderer("tiny")


def test_entry_point_to_something_that_is_not_a_renderer_is_a_rig_error(site):
    site.install("not-a-renderer", "not_a_renderer", "class Thing:\n    pass\n", "rig.renderers", "thing = not_a_renderer:Thing")
    with pytest.raises(RigError, match=r"not-a-renderer 0\.1.*does not satisfy"):
        make_renderer("thing")


def test_name_registered_by_two_distributions_is_a_rig_error(site):
    site.install("tiny-renderer", "tiny_renderer", TINY_RENDERER, "rig.renderers", "tiny = tiny_renderer:TinyRenderer")
    site.install("not-a-renderer", "not_a_renderer", "class Thing:\n    pass\n", "rig.renderers", "tiny = not_a_renderer:Thing")
    with pytest.raises(RigError, match=r"several.*not-a-renderer 0\.1.*tiny-renderer 0\.1|several.*tiny-renderer 0\.1.*not-a-renderer 0\.1"):
        make_renderer("tiny")


def test_built_in_name_wins_over_an_entry_point(site):
    site.install("tiny-renderer", "tiny_renderer", TINY_RENDERER, "rig.renderers", "direct = tiny_renderer:TinyRenderer")
    assert renderer_names().count("direct") == 1
    assert isinstance(make_renderer("direct"), DirectRenderer)


OPTION_RENDERER = '''
import numpy as np

from rig.render.protocol import AppFrameResult


class ShadeRenderer:
    """Fills the frame with one grey level, an option."""

    name = "shade"
    per_display_frame = False

    def __init__(self, level=128):
        self.level = level

    def open(self, setup):
        self.shape = (setup.height, setup.width, 3)

    def render_app_frame(self, request):
        return AppFrameResult(0.001, request.predict(request.t_photon), np.full(self.shape, self.level, dtype=np.uint8))

    def render_display_frame(self, request):
        raise RuntimeError("shade shows application frames only")

    def close(self):
        pass
'''


def test_a_spec_with_options_makes_a_configured_warp_renderer():
    renderer = make_renderer("warp:holes=2,recon=grid,views=2,fill=lowpass,spin=12.5")
    assert isinstance(renderer, WarpRenderer)
    assert renderer.options == WarpOptions(views=2, recon="grid", holes=2, fill="lowpass", spin=12.5)
    assert renderer.options.spec() == "warp:views=2,recon=grid,holes=2,fill=lowpass,spin=12.5"
    assert make_renderer(renderer.options.spec()).options == renderer.options
    assert make_renderer("warp").options == WarpOptions() and WarpOptions().spec() == "warp"


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("warp:wings=2", r"renderer 'warp' has no option 'wings'; its options: views, recon, holes, fill, border, untracked, spin"),
        ("warp:holes", r"key=value separated by commas, got 'holes'"),
        ("warp:holes=9", r"warp option holes must be one of 0, 1, 2, got 9"),
        ("warp:recon=voxel", r"warp option recon must be one of point, quad, mesh, grid"),
        ("direct:views=2", r"renderer 'direct' has no option 'views'; it takes no options"),
        ("nope:views=2", r"unknown renderer 'nope'"),
    ],
)
def test_bad_specs_are_config_errors_that_say_what_is_allowed(spec, message):
    with pytest.raises(ConfigError, match=message):
        make_renderer(spec)


def test_a_third_party_renderer_takes_its_options_as_keyword_arguments(site):
    site.install("shade-renderer", "shade_renderer", OPTION_RENDERER, "rig.renderers", "shade = shade_renderer:ShadeRenderer")
    assert make_renderer("shade:level=40").level == 40 and make_renderer("shade").level == 128
    with pytest.raises(ConfigError, match=r"renderer 'shade' has no option 'hue'; its options: level"):
        make_renderer("shade:hue=3")
    site.install("tiny-renderer", "tiny_renderer", TINY_RENDERER, "rig.renderers", "tiny = tiny_renderer:TinyRenderer")
    with pytest.raises(ConfigError, match=r"renderer 'tiny' has no option 'level'; it takes no options"):
        make_renderer("tiny:level=40")
