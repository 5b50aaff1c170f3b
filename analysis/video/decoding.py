"""Decoding frames a few ahead of their consumer, on a few threads, and Motion-JPEG packets to grey.

Motion-JPEG packets are decoded straight to grayscale with ``cv2.imdecode``: libjpeg then skips
chroma upsampling and colour conversion, which makes decoding about 1.7x faster than
``VideoCapture.read`` followed by a grey conversion. Once a crop is set, a packet is decoded only
as far as the crop needs (``analysis._jpeg_region``, the project's one compiled extension): the
tracking then costs less than the decoding it saves (``rig bench analyser`` compares the analysis
with decoding whole frames alone). Where that extension is not built (no libjpeg headers when the
package was installed) packets are decoded whole and cut: the same pixels, more slowly
(``REGION_DECODER_MISSING`` says so once per video). Packets and image files are decoded a few
frames ahead of the consumer by a few threads, the consumer's own among them (OpenCV and the
region decoder release the GIL while decoding), as many as OpenCV's own thread count allows: a
process meant to use one core (a Dask worker of one thread) sets that to 1 and decodes in the
consumer alone.
"""

from __future__ import annotations

import contextlib
import itertools
from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Generic, TypeVar

import cv2
import numpy as np

from analysis.errors import AnalysisError
from analysis.video.frames import Crop

try:
    from analysis._jpeg_region import decode_grey
except ImportError:
    decode_grey = None

# The most threads decoding frames, the consumer's among them, and how many frames they may run
# ahead of the consumer (enough to keep them busy while the consumer finds the ROIs in the first frames).
MAX_DECODE_THREADS = 4
READ_AHEAD = 64
# Frames handed to a thread at a time: threads exchange work once per batch, not once per frame.
DECODE_BATCH = 8
REGION_DECODER_MISSING = (
    "analysis._jpeg_region is not built, so Motion-JPEG frames are decoded whole: slower, same result; "
    "to build it, install libjpeg62-turbo-dev and reinstall the package (pip install -e .)"
)

_Item = TypeVar("_Item")


def decodes_regions() -> bool:
    """Whether a JPEG's rectangle is decoded alone (the compiled region decoder is built)."""
    return decode_grey is not None


def decode_threads() -> int:
    """Threads that decode frames, the consumer's among them: OpenCV's thread count (the cores this
    process may run on, unless ``cv2.setNumThreads`` or OPENCV_FOR_THREADS_NUM says otherwise), at
    most ``MAX_DECODE_THREADS``."""
    return max(1, min(MAX_DECODE_THREADS, cv2.getNumThreads()))


def decode_jpeg(packet: np.ndarray, crop: Crop | None) -> np.ndarray | None:
    """A grey frame from one JPEG packet: only the crop's rectangle once it is set and the region
    decoder is built, else the whole frame (see ``Crop``); None if it cannot be decoded."""
    region = crop.region if crop is not None else None
    if region is not None and decode_grey is not None:
        rows, cols = region
        rectangle = np.empty((rows.stop - rows.start, cols.stop - cols.start), dtype=np.uint8)
        if decode_grey(packet, rows.start, cols.start, rectangle, *rectangle.shape):
            return rectangle
    return cv2.imdecode(packet, cv2.IMREAD_GRAYSCALE)


@dataclass
class _Batch(Generic[_Item]):
    """Consecutive items, the worker's task mapping them, and their results if the consumer mapped them."""

    items: list[_Item]
    task: Future[list[np.ndarray | None]]
    results: list[np.ndarray | None] | None = None


def ordered_map(
    function: Callable[[_Item], np.ndarray | None], items: Iterable[_Item], describe: Callable[[int], str]
) -> Iterator[np.ndarray]:
    """function(item) for each item, in order: computed a few items ahead on ``decode_threads()``
    threads, or by the consumer alone, one item at a time, where that is 1.

    A None result is a frame that cannot be decoded: AnalysisError naming it via ``describe``.
    """
    threads = decode_threads()
    mapped = _mapped_ahead(function, items, threads - 1) if threads > 1 else (function(item) for item in items)
    with contextlib.closing(mapped):
        for index, result in enumerate(mapped):
            if result is None:
                raise AnalysisError(f"{describe(index)} is corrupt; re-record it or leave it out")
            yield result


def _mapped_ahead(
    function: Callable[[_Item], np.ndarray | None], items: Iterable[_Item], helpers: int
) -> Generator[np.ndarray | None, None, None]:
    """function(item) for each item, computed a few items ahead, yielded in order.

    Items are handed to `helpers` threads DECODE_BATCH at a time. The consumer maps items too: while
    the batch it needs next is still being mapped, it takes the earliest batch that no helper has
    started and maps it itself. So no core idles while the consumer works on a frame (tracking),
    and no more threads compete for the cores than there are (an extra one would be preempted
    while it holds the GIL, stalling the others).
    """

    def run(batch: list[_Item]) -> list[np.ndarray | None]:
        return [function(item) for item in batch]

    iterator = iter(items)
    batches = iter(lambda: list(itertools.islice(iterator, DECODE_BATCH)), [])
    pending: deque[_Batch[_Item]] = deque()
    pool = ThreadPoolExecutor(max_workers=helpers)
    try:
        while True:
            while len(pending) * DECODE_BATCH < READ_AHEAD and (batch := next(batches, None)) is not None:
                pending.append(_Batch(batch, pool.submit(run, batch)))
            if not pending:
                return
            head = pending[0]
            while head.results is None and not head.task.done():
                unstarted = next((b for b in pending if b.results is None and b.task.cancel()), None)
                if unstarted is None:
                    break
                unstarted.results = run(unstarted.items)
            pending.popleft()
            yield from head.task.result() if head.results is None else head.results
    finally:
        pool.shutdown(cancel_futures=True)
