"""A corpus of recordings, each labelled with the device that recorded it, the person and the scene.

A predictor chosen on some people must be judged on others: the labels say which recordings go
together. They come from a manifest where there is one, else from the file names.

Manifest: `manifest.csv` in the corpus folder, or a file given, with the header
`file,device,person,scene,apart` and one row per recording: its path from the corpus folder, the
device's name, the person's (unique within the corpus), the scene's (may be empty), and `apart`
`yes` for a recording not of a person wearing a headset (a robot replaying motion, a simulation):
such a recording is scored and reported apart, never grouped. Every CSV file in the folder must
have a row.

File names, without a manifest (`*.csv` in the folder and one level of subfolders):

* in a subfolder `SET/`, `SET_SCENE_PERSON.csv`: device SET, scene SCENE, person SET/PERSON (the
  same person in another scene is the same person);
* at the top, `NAME_PERSON.csv` where PERSON is `user` and digits: device NAME, person NAME/PERSON,
  no scene; any other top-level name is its own device and person;
* a name with the word `robot` in it is apart.
"""

from __future__ import annotations

import csv
import os
import re
from dataclasses import dataclass
from pathlib import Path

from predictors.errors import PredictorError
from predictors.trace import Trace, read_trace

MANIFEST = "manifest.csv"
MANIFEST_COLUMNS = ("file", "device", "person", "scene", "apart")
GROUPINGS = ("person", "scene", "device")
_PERSON = re.compile(r"user\d+")


@dataclass(frozen=True)
class Recording:
    """One recording and its labels (scene None where it has none)."""

    trace: Trace
    device: str
    person: str
    scene: str | None
    apart: bool

    @property
    def name(self) -> str:
        """The trace's name (the file's name without .csv)."""
        return self.trace.name

    def group(self, by: str) -> str | None:
        """Its group under one of `GROUPINGS` (None: it has no scene, or it is apart)."""
        if self.apart:
            return None
        return {"person": self.person, "scene": self.scene, "device": self.device}[by]


@dataclass(frozen=True)
class Labels:
    """What a manifest row or a file name says of a recording."""

    device: str
    person: str
    scene: str | None
    apart: bool


def labels_from_name(path: Path, folder: Path) -> Labels:
    """A recording's labels from its file name and subfolder (the module docstring gives the rules)."""
    stem = path.stem
    words = stem.split("_")
    apart = "robot" in words
    relative = path.relative_to(folder)
    if len(relative.parts) == 2:
        dataset = relative.parts[0]
        rest = stem[len(dataset) + 1:].split("_") if stem.startswith(dataset + "_") else []
        if len(rest) != 2 or not all(rest):
            raise PredictorError(f"{relative}: a recording in {dataset}/ must be named {dataset}_SCENE_PERSON.csv "
                                 f"(or be listed in a {MANIFEST})")
        return Labels(dataset, f"{dataset}/{rest[1]}", rest[0], apart)
    if len(words) > 1 and _PERSON.fullmatch(words[-1]):
        device = "_".join(words[:-1])
        return Labels(device, f"{device}/{words[-1]}", None, apart)
    return Labels(stem, stem, None, apart)


def read_manifest(path: Path) -> dict[str, Labels]:
    """The manifest's labels by file (as written in it); PredictorError naming a bad line."""
    try:
        with open(path, newline="", encoding="utf-8") as file:
            rows = list(csv.reader(file))
    except (OSError, UnicodeDecodeError) as error:
        raise PredictorError(f"cannot read the corpus manifest {path}: {error}") from None
    if not rows or tuple(c.strip() for c in rows[0]) != MANIFEST_COLUMNS:
        raise PredictorError(f"{path}: a corpus manifest's first line must be {','.join(MANIFEST_COLUMNS)}")
    labels = {}
    for number, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        cells = [c.strip() for c in row]
        if len(cells) != len(MANIFEST_COLUMNS) or not all(cells[:3]) or cells[4] not in ("yes", "no", ""):
            raise PredictorError(f"{path}, line {number}: expected file,device,person,scene,apart with the first "
                                 "three given and apart yes, no or empty")
        labels[cells[0]] = Labels(cells[1], cells[2], cells[3] or None, cells[4] == "yes")
    return labels


def read_corpus(folder: str | os.PathLike[str], manifest: str | os.PathLike[str] | None = None) -> list[Recording]:
    """Every recording in `folder` (top level and one level of subfolders), labelled by the manifest
    (`manifest`, else the folder's `manifest.csv` if any; never itself a recording) or by its name,
    in path order."""
    folder = Path(folder)
    if not folder.is_dir():
        raise PredictorError(f"corpus {folder} is not a folder of recordings")
    manifest_path = Path(manifest) if manifest is not None else folder / MANIFEST
    paths = sorted(p for p in (*folder.glob("*.csv"), *folder.glob("*/*.csv"))
                   if p.name != MANIFEST and p.resolve() != manifest_path.resolve())  # fmt: skip
    if not paths:
        raise PredictorError(f"corpus {folder} holds no .csv recordings (top level or one folder down)")
    listed = read_manifest(manifest_path) if manifest is not None or manifest_path.is_file() else None
    recordings = []
    for path in paths:
        relative = path.relative_to(folder).as_posix()
        if listed is None:
            labels = labels_from_name(path, folder)
        elif relative in listed:
            labels = listed[relative]
        else:
            raise PredictorError(f"{relative} is in the corpus but not in its manifest {manifest_path}: add a row for it")
        recordings.append(Recording(read_trace(path).in_time_order(), labels.device, labels.person, labels.scene, labels.apart))
    return recordings
