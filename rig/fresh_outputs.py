"""Outputs a failed run leaves behind only when it recorded something.

A run that fails before recording anything (a Dask scheduler nobody listens at, a device that
sends nothing, a predictor that fails on the first sample) would leave its folder holding empty
tables, and the same command would then be refused as "already holds a run". Within
`removed_unless_recorded`, a failure removes what the run made itself (files and folders that did
not exist before, parents of the output included) when nothing was recorded; a folder or file that
existed before is never removed, and a run that recorded something keeps everything.

Every record the rig makes is a CSV table written row by row as data arrives (a film's frames are
rows of its frame table), so a run recorded something exactly when a CSV file it made or rewrote
holds a row below its header.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

_HEAD_BYTES = 1 << 16


def _stamp(path: Path) -> tuple[int, int, int]:
    status = path.stat()
    return status.st_ino, status.st_mtime_ns, status.st_size


def _tree(root: Path) -> list[Path]:
    """`root` and everything under it, parents before children; [] when it does not exist."""
    if root.is_dir() and not root.is_symlink():
        return [root, *sorted(root.rglob("*"))]
    return [root] if root.exists() or root.is_symlink() else []


def _holds_rows(table: Path) -> bool:
    try:
        with table.open("rb") as stream:
            lines = stream.read(_HEAD_BYTES).split(b"\n")
    except OSError:
        return True  # cannot tell: keep it
    return any(line.strip() for line in lines[1:])


@dataclass(frozen=True)
class _Before:
    """What was at one output (and above it) before the run."""

    root: Path
    made_parents: tuple[Path, ...]
    """The output's missing ancestors, deepest first: the run makes them."""
    stamps: dict[Path, tuple[int, int, int] | None]
    """Each path under the output then: a file's identity, size and time; None for a folder."""

    @classmethod
    def of(cls, output: Path) -> _Before:
        root = output.absolute()
        missing = []
        parent = root.parent
        while not parent.exists() and parent != parent.parent:
            missing.append(parent)
            parent = parent.parent
        stamps = {path: None if path.is_dir() else _stamp(path) for path in _tree(root)}
        return cls(root, tuple(missing), stamps)

    def written(self) -> list[Path]:
        """The files under the output that the run made or changed."""
        return [p for p in _tree(self.root) if not p.is_dir() and (p not in self.stamps or self.stamps[p] != _stamp(p))]

    def undo(self) -> None:
        """Remove what the run made: new files, then new folders left empty, deepest first."""
        for path in reversed(_tree(self.root)):
            if path in self.stamps:
                continue
            try:
                path.rmdir() if path.is_dir() and not path.is_symlink() else path.unlink()
            except OSError:
                pass  # something else wrote there meanwhile, or it is gone already: leave it
        for parent in self.made_parents:
            try:
                parent.rmdir()
            except OSError:
                return


@contextmanager
def removed_unless_recorded(*outputs: Path) -> Iterator[None]:
    """Run the block; if it raises before any of `outputs` (folders or files) recorded a row,
    remove what it made there (see the module docstring) and let the error go on."""
    before = [_Before.of(Path(output)) for output in outputs]
    try:
        yield
    except Exception:
        written = [path for output in before for path in output.written()]
        if not any(path.suffix.lower() == ".csv" and _holds_rows(path) for path in written):
            for output in before:
                output.undo()
        raise
