"""Output paths checked before any work, and writes after it that cannot lose the result.

Each checker is an argparse `type`: a bad --out, --json FILE, --csv or --plot is refused while the
command line is read, in one line naming the option as typed, before a video is decoded or a fit
compiled. A path passes when whatever the command will create there can be created: a file's
folder exists and takes a new file, a folder's nearest existing ancestor takes one, a file is not
a folder and a folder not a file, and a file's extension is one the command can write.

`LateWrites` is for the writes that come after the work: one that still fails (a full disk, a
folder removed meanwhile) is noted while the others go ahead and the result is printed; the
command then ends with one line saying what was not written (exit status 2).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import tempfile
from pathlib import Path
from typing import Callable

from rig.errors import ConfigError, RigError


def nearest_existing(path: Path) -> Path:
    """`path`, or the nearest path above it that exists (a folder to be made is made there)."""
    path = path.absolute()
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def _writable_folder(folder: Path) -> str | None:
    """Why a new file cannot be made in `folder`, or None when it can (tried, not guessed from
    permission bits: a read-only mount or /proc refuses even root)."""
    if not folder.is_dir():
        return f"{folder} is not a folder"
    try:
        handle, probe = tempfile.mkstemp(prefix=".rig-write-check-", dir=folder)
    except OSError as error:
        return f"cannot create files in {folder} ({error.strerror or error})"
    os.close(handle)
    os.unlink(probe)
    return None


def output_folder(text: str) -> Path:
    """An output folder: an existing folder, or one that can be made (its nearest existing
    ancestor is a folder that takes new entries)."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{path} is a file, not a folder; choose an output folder")
    problem = _writable_folder(nearest_existing(path))
    if problem is not None:
        raise argparse.ArgumentTypeError(f"cannot write into {path}: {problem}")
    return path


def output_file(*suffixes: str) -> Callable[[str], Path]:
    """The argparse type of an output file with one of `suffixes` (any when none are given)."""

    def check(text: str) -> Path:
        path = Path(text)
        if path.is_dir():
            raise argparse.ArgumentTypeError(f"{path} is a folder; name the file to write in it")
        if suffixes and path.suffix.lower() not in suffixes:
            which = suffixes[0] if len(suffixes) == 1 else f"one of {', '.join(suffixes)}"
            raise argparse.ArgumentTypeError(f"{path} must end in {which}")
        if not path.parent.exists():
            raise argparse.ArgumentTypeError(f"cannot write {path}: folder {path.parent} does not exist")
        problem = _writable_folder(path.parent)
        if problem is not None:
            raise argparse.ArgumentTypeError(f"cannot write {path}: {problem}")
        return path

    check.__name__ = "output file"
    return check


def plot_suffixes() -> tuple[str, ...]:
    """The extensions the plots can be saved as (matplotlib's formats)."""
    from matplotlib.figure import Figure

    return tuple(sorted(f".{kind}" for kind in Figure().canvas.get_supported_filetypes()))


def plot_file(text: str) -> Path:
    """The argparse type of a plot to write: a file in a format matplotlib writes (.png, .pdf, .svg, ...)."""
    return output_file(*plot_suffixes())(text)


def checked(kind: Callable[[str], Path], path: Path, option: str) -> Path:
    """`kind`'s check (one of the types above) made by a command itself, where its parser did not
    make it: ConfigError naming `option` as the user typed it."""
    try:
        return kind(str(path))
    except argparse.ArgumentTypeError as error:
        raise ConfigError(f"argument {option}: {error}") from None


json_file = output_file(".json")
csv_file = output_file(".csv")


class LateWrites:
    """The writes a command makes once its work is done. A failing one is noted and the rest go
    ahead; `check` then raises one RigError naming every output that was not written."""

    def __init__(self) -> None:
        self.failed: list[str] = []

    def write(self, path: Path, write: Callable[[], object]) -> None:
        """Run `write`, which writes `path`; note an OSError (or matplotlib's ValueError) instead of raising it."""
        try:
            write()
        except (OSError, ValueError) as error:
            reason = error.strerror if isinstance(error, OSError) and error.strerror else str(error)
            self.failed.append(f"cannot write {path} ({reason})")

    def json(self, path: Path, record: object) -> None:
        """Write `record` as indented JSON to `path`, as `write` does."""
        self.write(path, lambda: path.write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8"))

    def csv(self, path: Path, rows: list[dict[str, object]]) -> None:
        """Write `rows` as CSV to `path`, a column per field any row has in the order they first appear, as `write` does."""

        def write() -> None:
            with path.open("w", newline="", encoding="utf-8") as stream:
                writer = csv.DictWriter(stream, fieldnames=list(dict.fromkeys(key for row in rows for key in row)))
                writer.writeheader()
                writer.writerows(rows)

        self.write(path, write)

    def check(self) -> None:
        """RigError if any write failed; the result has been printed by then."""
        if self.failed:
            raise RigError("; ".join(self.failed) + "; the result above stands, the other outputs were written")
