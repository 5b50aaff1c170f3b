"""Shared by the rig's tests: third-party plug-ins installed into a throw-away site folder."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path
from typing import Iterator

import pytest


class PluginSite:
    """A folder on sys.path that importlib.metadata scans for installed distributions."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.modules: list[str] = []

    def install(self, distribution: str, module: str, source: str, group: str, entry_points: str) -> None:
        """Lay out a distribution (its module plus dist-info, entry points in `group`), as pip would."""
        (self.root / f"{module}.py").write_text(textwrap.dedent(source))
        dist_info = self.root / f"{distribution}-0.1.dist-info"
        dist_info.mkdir()
        (dist_info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {distribution}\nVersion: 0.1\n")
        (dist_info / "entry_points.txt").write_text(f"[{group}]\n{entry_points}\n")
        self.modules.append(module)


@pytest.fixture
def site(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[PluginSite]:
    monkeypatch.syspath_prepend(tmp_path)
    plugins = PluginSite(tmp_path)
    yield plugins
    for module in plugins.modules:
        sys.modules.pop(module, None)
