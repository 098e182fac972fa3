"""SUMO additional files of detectors: the writer the E1 loops share (:mod:`.loops`)."""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

from arzsumo.io import atomic_file


def write_additional(path: Path, tag: str, elements: list[dict[str, str]]) -> Path:
    """Write a SUMO additional file of ``<tag .../>`` elements (attributes as given),
    atomically, and return its path."""
    lines = ["    <" + tag + " " + " ".join(f"{a}={quoteattr(v)}" for a, v in e.items()) + "/>"
             for e in elements]
    with atomic_file(path) as tmp:
        tmp.write_text("<additional>\n" + "\n".join(lines) + "\n</additional>\n",
                       encoding="utf-8")
    return path
