"""An MkDocs hook that renders the notebooks in notebooks/ as pages under notebooks/ of the site.

Each notebook becomes Markdown at build time: its Markdown cells as they are, its code cells as
Python blocks, any saved text output after its cell. No Jupyter is needed to build the site.
"""

from __future__ import annotations

import json
from pathlib import Path

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"


def notebook_markdown(notebook: dict, name: str) -> str:
    """The notebook as one Markdown page, a note on how to run it after its first cell."""
    parts = []
    for index, cell in enumerate(notebook["cells"]):
        source = "".join(cell["source"]).rstrip()
        if cell["cell_type"] == "markdown":
            parts.append(source)
        elif cell["cell_type"] == "code":
            parts.append(f"```python\n{source}\n```")
            text = "".join("".join(output.get("text", "")) for output in cell.get("outputs", []))
            if text.strip():
                parts.append(f"```text\n{text.rstrip()}\n```")
        if index == 0:
            parts.append(
                f"*This page is `notebooks/{name}`, shown without its output. Run it with `make notebooks`, "
                "which installs Jupyter and executes every notebook, or open it in Jupyter.*"
            )
    return "\n\n".join(parts) + "\n"


def on_files(files: Files, config: MkDocsConfig) -> Files:
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        notebook = json.loads(path.read_text(encoding="utf-8"))
        files.append(File.generated(config, f"notebooks/{path.stem}.md", content=notebook_markdown(notebook, path.name)))
    return files
