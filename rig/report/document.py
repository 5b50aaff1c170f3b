"""A report as plain content (headline, sections of text, tables and figures), written as one
self-contained HTML page (figures embedded as PNG, no network) and as Markdown for a lab notebook
(figures as PNG files in a folder beside it)."""

from __future__ import annotations

import base64
import html
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

from matplotlib.figure import Figure

from rig.errors import RigError

Table = tuple[Sequence[str], Sequence[Sequence[Any]]]


@dataclass
class Section:
    """A heading and its blocks, in order: text (str), tables (header, rows) and figures (name, Figure)."""

    heading: str
    blocks: list[str | Table | tuple[str, Figure]] = field(default_factory=list)


@dataclass
class Report:
    title: str
    headline: str
    verdict: str
    sections: list[Section] = field(default_factory=list)


def cell(value: Any) -> str:
    """A table's value as people read it: a number to four significant figures (nothing below a
    billionth, so a rounding error reads 0), yes or no for a
    flag, a list's items joined, "-" for none; text a CSV summary kept of these ("False",
    "[0.0, 9.99]", "9.991666666666667") reads the same."""
    if isinstance(value, str):
        value = _read_back(value)
    if value is None or value == "":
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{round(value, 9) + 0.0:.4g}" if math.isfinite(value) else str(value)  # + 0.0: no "-0"
    if isinstance(value, (list, tuple)):
        return ", ".join(map(cell, value)) or "-"
    if isinstance(value, dict):
        return ", ".join(f"{key} {cell(item)}" for key, item in value.items()) or "-"
    return str(value)


def _read_back(text: str) -> Any:
    """The value a CSV cell wrote as text (a flag, a number, a list), or the text itself."""
    if text in ("True", "False"):
        return text == "True"
    if text.startswith("[") and text.endswith("]"):
        try:
            return json.loads(text)
        except ValueError:
            return text
    if any(mark in text for mark in ".eE") and not text.lower().startswith(("inf", "nan")):
        try:
            return float(text)
        except ValueError:
            return text
    return text


def _png(figure: Figure) -> bytes:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100)
    return buffer.getvalue()


_STYLE = """
body { font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }
.headline { font-size: 2.6em; font-weight: 600; margin: 0.2em 0; }
.verdict { font-size: 1.1em; padding: 0.4em 0.8em; border-radius: 4px; background: #eef; display: inline-block; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
img { max-width: 100%; }
"""


def write_html(report: Report, path: Path) -> None:
    """One self-contained page: everything in the file, nothing fetched."""
    parts = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>{html.escape(report.title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{html.escape(report.title)}</h1>",
        f"<div class='headline'>{html.escape(report.headline)}</div>",
        f"<div class='verdict'>{html.escape(report.verdict)}</div>",
    ]
    for section in report.sections:
        parts.append(f"<h2>{html.escape(section.heading)}</h2>")
        for block in section.blocks:
            if isinstance(block, str):
                parts.append(f"<p>{html.escape(block)}</p>")
            elif isinstance(block[1], Figure):
                name, figure = block
                data = base64.b64encode(_png(figure)).decode("ascii")
                parts.append(f"<img alt='{html.escape(name)}' src='data:image/png;base64,{data}'>")
            else:
                header, rows = block
                parts.append("<table><tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in header) + "</tr>")
                parts += ["<tr>" + "".join(f"<td>{html.escape(cell(v))}</td>" for v in row) + "</tr>" for row in rows]
                parts.append("</table>")
    parts.append("</body></html>")
    _write(path, "\n".join(parts).encode("utf-8"))


def write_markdown(report: Report, path: Path) -> None:
    """Markdown with the figures as PNG files in `<name>_files/` beside it."""
    folder = path.with_name(path.stem + "_files")
    lines = [f"# {report.title}", "", f"**{report.headline}**", "", f"_{report.verdict}_", ""]
    for section in report.sections:
        lines += [f"## {section.heading}", ""]
        for block in section.blocks:
            if isinstance(block, str):
                lines += [block, ""]
            elif isinstance(block[1], Figure):
                name, figure = block
                folder.mkdir(exist_ok=True)
                _write(folder / f"{name}.png", _png(figure))
                lines += [f"![{name}]({folder.name}/{name}.png)", ""]
            else:
                header, rows = block
                lines.append("| " + " | ".join(str(h) for h in header) + " |")
                lines.append("|" + "---|" * len(header))
                lines += ["| " + " | ".join(cell(v).replace("|", "/") for v in row) + " |" for row in rows]
                lines.append("")
    _write(path, "\n".join(lines).encode("utf-8"))


def _write(path: Path, data: bytes) -> None:
    try:
        path.write_bytes(data)
    except OSError as error:
        raise RigError(f"cannot write {path}: {error.strerror}") from None
