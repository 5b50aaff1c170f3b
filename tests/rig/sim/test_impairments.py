"""The simulated camera's impairments of its film: each frame changed as the lab's camera would."""

import numpy as np
import pytest

from rig.errors import ConfigError
from rig.sim.impairments import OCCLUDER_FRACTION, FrameImpairer
from rig.sim.impairments_config import FilmImpairments

HEIGHT, WIDTH = 48, 64
LED_ROI, SPHERE_ROI = (4, 10, 24, 20), (36, 12, 24, 18)
BACKGROUND = np.full((HEIGHT, WIDTH), 8, dtype=np.uint8)
BACKGROUND[:, 32:] = 14


def _impairer(exposures: int = 40, seed: int = 3, **settings) -> FrameImpairer:
    return FrameImpairer(FilmImpairments(**settings), BACKGROUND, {"led": LED_ROI, "sphere": SPHERE_ROI}, exposures, seed)


def _frame(seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).integers(20, 255, (HEIGHT, WIDTH), dtype=np.uint8)


def test_no_impairment_films_the_sensors_frames_as_they_are() -> None:
    impair = _impairer()
    frame = _frame()
    assert impair(0, frame) is frame


def test_a_decimated_film_keeps_every_nth_exposure_from_the_first_frame() -> None:
    impair = _impairer(every_nth=4, first_frame=3)
    kept = [index for index in range(20) if impair(index, _frame()) is not None]
    assert kept == [3, 7, 11, 15, 19]


def test_a_mirrored_film_puts_the_led_on_the_right() -> None:
    frame = _frame()
    np.testing.assert_array_equal(_impairer(mirrored=True)(0, frame), frame[:, ::-1])
    assert FilmImpairments(mirrored=True).film_rect(LED_ROI, WIDTH) == (WIDTH - 4 - 24, 10, 24, 20)
    assert FilmImpairments().film_rect(LED_ROI, WIDTH) == LED_ROI


def test_a_dim_led_scales_the_left_half_only_after_saturation() -> None:
    frame = np.full((HEIGHT, WIDTH), 255, dtype=np.uint8)
    dimmed = _impairer(dim_led=0.35)(0, frame)
    assert (dimmed[:, : WIDTH // 2] == 89).all()  # a saturated LED films at 255 * 0.35, below a 190 DN sphere
    assert (dimmed[:, WIDTH // 2 :] == 255).all()


def test_a_bar_shows_the_background_across_the_blobs_path_and_nowhere_else() -> None:
    frame = _frame()
    hidden = _impairer(occluded="sphere")(0, frame)
    x, y, w, h = SPHERE_ROI
    left, width = x + w // 3, max(2, round(OCCLUDER_FRACTION * w))
    assert (hidden[y : y + h, left : left + width] == 14).all()
    changed = hidden != frame
    changed[y : y + h, left : left + width] = False
    assert not changed.any()


def test_the_missing_sphere_is_hidden_in_its_share_of_frames_drawn_by_the_seed() -> None:
    def hidden_frames(seed: int) -> list[int]:
        impair = _impairer(exposures=200, seed=seed, missing_fraction=0.05)
        x, y, w, h = SPHERE_ROI
        return [i for i in range(200) if (impair(i, _frame(i))[y : y + h, x : x + w] == 14).all()]

    assert len(hidden_frames(3)) == 10
    assert hidden_frames(3) == hidden_frames(3) != hidden_frames(4)


def test_blur_spreads_a_point_of_light() -> None:
    frame = np.zeros((HEIGHT, WIDTH), dtype=np.uint8)
    frame[24, 32] = 255
    blurred = _impairer(blur_sigma_px=2.5)(0, frame)
    assert blurred[24, 32] < 40 and blurred[24, 35] > 0 and blurred.sum() == pytest.approx(255, rel=0.1)


def test_a_bright_object_saturates_between_and_above_the_halves() -> None:
    lit = _impairer(bright_object_dn=900.0)(0, np.zeros((HEIGHT, WIDTH), dtype=np.uint8))
    assert lit[HEIGHT // 8, WIDTH // 2] == 255
    assert lit[HEIGHT - 1, 0] == 0


@pytest.mark.parametrize(
    "bad",
    [dict(blur_sigma_px=-1.0), dict(dim_led=0.0), dict(dim_led=1.5), dict(occluded="pendulum"), dict(missing_fraction=1.0),
     dict(every_nth=0), dict(every_nth=4, first_frame=4), dict(bright_object_dn=-1.0)],
)  # fmt: skip
def test_bad_impairments_are_rejected(bad: dict) -> None:
    with pytest.raises(ConfigError):
        FilmImpairments(**bad)
