"""An MkDocs hook that lets pages link to the repository's own files, as they do on GitHub.

A relative link from a page to a file outside docs/ that exists in the repository (an example, a
profile, the firmware's README) works when the Markdown is read in the repository, but is no page
of the site: on the site it becomes the file's path in code. A link to a file that does not exist
is left alone, so the strict build still fails on it.
"""

from __future__ import annotations

import re
from pathlib import Path

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import Files
from mkdocs.structure.pages import Page

LINK = re.compile(r"(?<!!)\[([^\]\n]+)\]\(([^)\s#]+)(#[^)\s]*)?\)")
FENCE = re.compile(r"^(```|~~~)", re.MULTILINE)


def outside_links_as_paths(markdown: str, page_dir: Path, docs_dir: Path, root: Path) -> str:
    """`markdown` with each link to an existing repository file outside `docs_dir` written as its path."""

    def rewrite(match: re.Match[str]) -> str:
        text, target = match.group(1), match.group(2)
        if "://" in target or target.startswith("mailto:"):
            return match.group(0)
        path = (page_dir / target).resolve()
        if path.is_relative_to(docs_dir) or not path.is_relative_to(root) or not path.exists():
            return match.group(0)
        shown = f"`{path.relative_to(root).as_posix()}{'/' if path.is_dir() else ''}`"
        return shown if text.strip("`") in shown else f"{text} ({shown})"

    parts = FENCE.split(markdown)
    # FENCE.split keeps each fence marker: text, marker, code, marker, text, ...; only text is rewritten.
    return "".join(LINK.sub(rewrite, part) if index % 4 == 0 else part for index, part in enumerate(parts))


def on_page_markdown(markdown: str, page: Page, config: MkDocsConfig, files: Files) -> str:
    docs_dir = Path(config.docs_dir).resolve()
    root = Path(config.config_file_path).resolve().parent
    page_dir = (docs_dir / page.file.src_uri).parent
    return outside_links_as_paths(markdown, page_dir, docs_dir, root)
