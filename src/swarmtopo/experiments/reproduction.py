"""What a reproduced experiment writes: its table (CSV), summary (Markdown, JSON) and
figures in one output folder (shared by :mod:`.reproduce` and :mod:`.clust`)."""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._json import jsonable, write_json
from ..errors import SwarmtopoError


@dataclass(frozen=True)
class Reproduction:
    """What one reproduced experiment wrote and found.

    Attributes
    ----------
    name
        Experiment name (a key of :data:`~.reproduce.REPRODUCTIONS`).
    figures
        PNG files written.
    table
        The CSV file of results.
    table_markdown
        The summary table in Markdown.
    summary
        Headline numbers (JSON-able).
    settings
        Everything the numbers depend on (JSON-able).
    """

    name: str
    figures: list[Path]
    table: Path
    table_markdown: str
    summary: dict[str, Any]
    settings: dict[str, Any] = field(default_factory=dict)


def output_folder(out) -> Path:
    """``out`` as a Path, created (one-line SwarmtopoError if it cannot be)."""
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SwarmtopoError(f"cannot create the output folder {str(out)!r}: {exc.strerror or exc}") from None
    return out


def _markdown(headers: list[str], cells: list[list]) -> str:
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in cells]
    return "\n".join(lines) + "\n"


def _write_csv(path: Path, rows: list[dict[str, Any]]) -> Path:
    """One row per run; floats written in full (``repr``), None as empty."""
    columns = list(dict.fromkeys(k for row in rows for k in row))
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: "" if row.get(k) is None else row[k] for k in columns})
    return path


def write_reproduction(name, out, rows, headers, cells, figures, summary, settings) -> Reproduction:
    """Write NAME.csv (``rows``), NAME.md (``headers`` x ``cells``) and NAME.json
    (summary and settings) into ``out``; the :class:`Reproduction` of them."""
    table = _write_csv(out / f"{name}.csv", rows)
    markdown = _markdown(headers, cells)
    (out / f"{name}.md").write_text(markdown, encoding="utf-8")
    write_json(jsonable({"name": name, "summary": summary, "settings": settings}), out / f"{name}.json")
    return Reproduction(name=name, figures=figures, table=table, table_markdown=markdown,
                        summary=jsonable(summary), settings=jsonable(settings))
