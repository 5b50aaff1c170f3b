"""Settings declared once (`declared`): ranges say what they allow and hold exactly that; a
dataclass checks its values against its declarations; a spec's table is read key by key."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from declared import FRACTION, NON_NEGATIVE, OPEN_UNIT, POSITIVE, Flag, Range, check, from_table, setting, walk

laws = settings(deadline=None, max_examples=50, derandomize=True)


@pytest.mark.parametrize(
    ("allowed", "unit", "words"),
    [
        (POSITIVE, "metres", "a positive number of metres"),
        (NON_NEGATIVE, "1/s", "zero or a positive number of 1/s"),
        (OPEN_UNIT, "", "a positive number below 1"),
        (FRACTION, "", "zero or a positive number below 1"),
        (Range(2.0), "seconds", "a positive number of seconds above 2"),
        (Range(2.0, includes_low=True), "seconds", "a positive number of seconds at least 2"),
        (Range(0.5, 3600.0, True, True), "seconds", "a positive number of seconds from 0.5 to 3600"),
        (Range(0.0, 45.0, includes_high=True), "degrees", "a positive number of degrees at most 45"),
        (Range(-5.0, 5.0), "ms", "a number of ms above -5 and below 5"),
        (Range(-math.inf), "seconds", "a number of seconds"),
    ],
)
def test_a_range_says_what_it_allows(allowed, unit, words):
    assert allowed.describe(unit) == words


@given(st.floats(allow_nan=True))
@example(0.0)
@example(1.0)
@example(math.inf)
@laws
def test_a_range_holds_exactly_what_it_describes(value):
    assert POSITIVE.contains(value) == (0.0 < value < math.inf)
    assert NON_NEGATIVE.contains(value) == (0.0 <= value < math.inf)
    assert OPEN_UNIT.contains(value) == (0.0 < value < 1.0)
    assert Range(0.0, math.inf, includes_high=True).contains(value) == (0.0 < value <= math.inf)
    assert Range(1.0, 2.0, True, True).scaled(1e3).contains(value) == (1e3 <= value <= 2e3)


class Wrong(Exception):
    pass


def _increasing(pair: tuple[float, float]) -> str | None:
    return None if pair[0] < pair[1] else "LOW must be below HIGH"


@dataclass(frozen=True)
class Lens:
    focus_m: float = setting(1.0, "metres", "focus distance", POSITIVE)

    def __post_init__(self) -> None:
        check(self, Wrong, "lens.")


@dataclass(frozen=True)
class Camera:
    fps: float = setting(120.0, "Hz", "frame rate", Range(1.0, 1000.0, True, True), flag="--fps")
    delay_s: float = setting(0.004, "seconds", "delay", NON_NEGATIVE, flag=Flag("--delay-ms", unit="ms", factor=1e3))
    cost_ms: float | None = setting(5.0, "ms", "cost, or measured", POSITIVE, none="measured")
    size: tuple[int, int] = setting((4, 3), "pixels", "width and height", POSITIVE)
    side: str | None = setting(None, "", "which side (default: either)", choices=("left", "right"))
    window: tuple[float, float] = setting((0.0, 1.0), "s", "window", rule=_increasing)
    lens: Lens = field(default_factory=Lens)
    raw: int = 7

    def __post_init__(self) -> None:
        check(self, Wrong, "camera.")


@pytest.mark.parametrize(
    ("settings_", "message"),
    [
        ({"fps": 0.5}, "camera.fps must be a positive number of Hz from 1 to 1000, got 0.5"),
        ({"fps": math.nan}, "camera.fps must be a positive number of Hz from 1 to 1000, got nan"),
        ({"fps": "fast"}, "camera.fps must be a positive number of Hz from 1 to 1000, got 'fast'"),
        ({"size": (4, 0)}, "camera.size must have each item a positive whole number of pixels, got (4, 0)"),
        ({"side": "top"}, "camera.side must be one of left, right, got 'top'"),
        ({"window": (1.0, 0.0)}, "camera.window: LOW must be below HIGH, got (1.0, 0.0)"),
        ({"delay_s": None}, "camera.delay_s must be given, got None"),
    ],
)
def test_a_value_its_setting_does_not_allow_is_one_line_naming_it(settings_, message):
    with pytest.raises(Wrong) as raised:
        Camera(**settings_)
    assert str(raised.value) == message


def test_none_is_a_value_only_where_the_type_allows_it():
    assert Camera(cost_ms=None, side=None).cost_ms is None


def test_walk_lists_every_declared_setting_with_its_default_nested_ones_at_their_place():
    entries = list(walk(Camera, Camera(lens=Lens(2.0))))
    assert [(e.path, e.default) for e in entries] == [
        ("fps", 120.0), ("delay_s", 0.004), ("cost_ms", 5.0), ("size", (4, 3)), ("side", None), ("window", (0.0, 1.0)),
        ("lens.focus_m", 2.0),
    ]  # fmt: skip
    assert [e.setting.flag for e in entries][:2] == [Flag("--fps"), Flag("--delay-ms", unit="ms", factor=1e3)]
    assert [e.default for e in walk(Camera)][-1] == 1.0


def test_a_table_sets_the_fields_it_names_and_leaves_the_defaults():
    camera = from_table(Camera, {"fps": 240, "cost_ms": "measured", "size": [8, 6], "lens": {"focus_m": 3}}, Wrong)
    assert camera == Camera(fps=240.0, cost_ms=None, size=(8, 6), lens=Lens(3.0))
    assert isinstance(camera.fps, float) and isinstance(camera.lens.focus_m, float)


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"fpss": 1}, "spec.toml: unknown key fpss; Camera takes fps, delay_s, cost_ms, size, side, window, lens, raw"),
        ({"lens": {"focus": 1}}, "spec.toml: unknown key lens.focus; Lens takes focus_m"),
        ({"fps": "fast"}, "spec.toml: fps must be a number, not 'fast'"),
        ({"fps": True}, "spec.toml: fps must be a number, not True"),
        ({"cost_ms": "measure"}, "spec.toml: cost_ms must be a number or \"measured\", not 'measure'"),
        ({"size": [1]}, "spec.toml: size must be a list of 2 items, each a whole number, not [1]"),
        ({"size": [1, 2.5]}, "spec.toml: size[1] must be a whole number, not 2.5"),
        ({"lens": 3}, "spec.toml: lens must be a table of Lens settings, not 3"),
        ({"fps": 0}, "spec.toml: camera.fps must be a positive number of Hz from 1 to 1000, got 0.0"),
        ({"lens": {"focus_m": -1}}, "spec.toml: lens.focus_m must be a positive number of metres, got -1.0"),
    ],
)
def test_a_bad_table_is_one_line_naming_the_key(table, message):
    with pytest.raises(Wrong) as raised:
        from_table(Camera, table, Wrong, "spec.toml")
    assert str(raised.value) == message
