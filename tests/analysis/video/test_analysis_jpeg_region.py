"""Decoding one rectangle of a JPEG (analysis._jpeg_region) against OpenCV's whole grey decode."""

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from analysis._jpeg_region import decode_grey

WIDTH, HEIGHT = 203, 117  # neither a multiple of 8 nor of 16: partial blocks on both edges


def scene(seed: int = 0) -> np.ndarray:
    """A BGR image with detail at every scale: noise, a gradient and bright blobs."""
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 60, (HEIGHT, WIDTH, 3)).astype(np.float64)
    image += np.linspace(0, 120, WIDTH)[None, :, None]
    cv2.circle(image, (50, 40), 9, (255, 240, 230), -1)
    cv2.circle(image, (160, 90), 14, (90, 200, 120), -1)
    return np.clip(image, 0, 255).astype(np.uint8)


ENCODINGS = {
    "colour 4:2:0": (scene(), []),
    "colour 4:4:4": (scene(), [cv2.IMWRITE_JPEG_SAMPLING_FACTOR, cv2.IMWRITE_JPEG_SAMPLING_FACTOR_444]),
    "colour 4:2:2": (scene(), [cv2.IMWRITE_JPEG_SAMPLING_FACTOR, cv2.IMWRITE_JPEG_SAMPLING_FACTOR_422]),
    "grey": (cv2.cvtColor(scene(), cv2.COLOR_BGR2GRAY), []),
    "progressive": (scene(), [cv2.IMWRITE_JPEG_PROGRESSIVE, 1]),
    "restart markers": (scene(), [cv2.IMWRITE_JPEG_RST_INTERVAL, 3]),
}


def encoded(name: str) -> np.ndarray:
    image, parameters = ENCODINGS[name]
    ok, data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 90, *parameters])
    assert ok
    return data.reshape(-1)


def region(data: np.ndarray, top: int, left: int, height: int, width: int) -> np.ndarray | None:
    out = np.empty((height, width), dtype=np.uint8)
    return out if decode_grey(data, top, left, out, height, width) else None


@st.composite
def rectangles(draw):
    top = draw(st.integers(0, HEIGHT - 1))
    left = draw(st.integers(0, WIDTH - 1))
    return top, left, draw(st.integers(1, HEIGHT - top)), draw(st.integers(1, WIDTH - left))


@pytest.mark.parametrize("name", list(ENCODINGS))
@settings(max_examples=40, deadline=None)
@given(rectangle=rectangles())
def test_a_rectangle_is_the_same_pixels_as_the_whole_grey_decode(name, rectangle):
    data = encoded(name)
    top, left, height, width = rectangle
    whole = cv2.imdecode(data, cv2.IMREAD_GRAYSCALE)
    assert np.array_equal(region(data, top, left, height, width), whole[top : top + height, left : left + width])


def without_huffman_tables(data: np.ndarray) -> np.ndarray:
    """The JPEG with its DHT segments taken out, as many USB cameras send Motion-JPEG frames."""
    data, kept, index = data.tobytes(), bytearray(data[:2].tobytes()), 2
    while data[index + 1] != 0xDA:  # every segment up to the start of scan
        length = int.from_bytes(data[index + 2 : index + 4], "big")
        if data[index + 1] != 0xC4:
            kept += data[index : index + 2 + length]
        index += 2 + length
    return np.frombuffer(bytes(kept + data[index:]), dtype=np.uint8)


def test_a_motion_jpeg_frame_without_huffman_tables_uses_the_standard_ones():
    data = without_huffman_tables(encoded("colour 4:2:0"))
    assert data.size < encoded("colour 4:2:0").size
    whole = cv2.imdecode(data, cv2.IMREAD_GRAYSCALE)
    assert np.array_equal(whole, cv2.imdecode(encoded("colour 4:2:0"), cv2.IMREAD_GRAYSCALE))
    assert np.array_equal(region(data, 20, 40, 60, 100), whole[20:80, 40:140])


def test_the_whole_image_as_a_rectangle_is_the_whole_decode():
    data = encoded("colour 4:2:0")
    assert np.array_equal(region(data, 0, 0, HEIGHT, WIDTH), cv2.imdecode(data, cv2.IMREAD_GRAYSCALE))


@pytest.mark.parametrize(
    "rectangle",
    [(HEIGHT - 10, 0, 11, 20), (0, WIDTH - 5, 10, 6), (-1, 0, 10, 10), (0, -3, 10, 10), (0, 0, 0, 10)],
    ids=["below", "right", "above", "left", "empty"],
)
def test_a_rectangle_outside_the_image_is_refused(rectangle):
    assert region(encoded("grey"), *rectangle) is None


def test_data_that_is_not_a_jpeg_is_refused():
    assert region(np.frombuffer(b"not a jpeg at all" * 20, dtype=np.uint8), 0, 0, 4, 4) is None


def test_a_truncated_jpeg_is_refused_where_the_rectangle_reaches_the_damage():
    # OpenCV refuses a truncated JPEG rather than show what libjpeg patches in; so does the region,
    # unless the rectangle ends above the damage, which is then never read.
    data = encoded("colour 4:2:0")
    cut = data[: data.size * 2 // 3]
    assert cv2.imdecode(cut, cv2.IMREAD_GRAYSCALE) is None
    assert region(cut, 50, 30, HEIGHT - 50, 150) is None
    whole = cv2.imdecode(data, cv2.IMREAD_GRAYSCALE)
    assert np.array_equal(region(cut, 0, 30, 16, 150), whole[:16, 30:180])


def test_an_output_buffer_of_the_wrong_size_raises():
    out = np.empty((10, 10), dtype=np.uint8)
    with pytest.raises(ValueError, match="height \\* width"):
        decode_grey(encoded("grey"), 0, 0, out, 10, 11)
