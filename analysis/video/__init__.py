"""Frame sources: a video file, a folder of numbered images, or an in-memory array.

``sources.open_frames`` picks the source for what the user gave; every source meets the contract
in ``frames`` (stamped grey frames in order, a ``Crop`` the consumer may set while reading, every
n-th frame on request). ``decoding`` decodes a few frames ahead on a few threads, and decodes only
the crop's rectangle of a Motion-JPEG frame where the compiled region decoder is built.
"""
