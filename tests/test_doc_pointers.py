"""Every pointer from the code to a page of the docs or the readings lands: the page exists
and, where a section is named (``docs/sumo.md, "Network"``), the page has that heading or
bold label."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = r"((?:docs|research/readings)/[\w/-]+\.md)"
# a section in double quotes, or in single quotes ending before punctuation or a space
SECTION = r"""(?:,\s*(?:section\s+)?(?:"([^"]+)"|'(.+?)'(?=[\s).,;:])))?"""
POINTER = re.compile(PAGE + SECTION)


def _pointers() -> list[tuple[str, str, str | None]]:
    found = []
    for path in sorted((ROOT / "src" / "arzsumo").rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        for m in POINTER.finditer(text):
            section = m.group(2) or m.group(3)
            found.append((str(path.relative_to(ROOT)), m.group(1),
                          " ".join(section.split()) if section else None))
    return found


def _headings(page: Path) -> list[str]:
    """The page's headings and its bold run-in labels (``**One warm-up per seed.**``)."""
    text = page.read_text(encoding="utf-8")
    heads = [line.lstrip("#") for line in text.splitlines() if line.startswith("#")]
    heads += re.findall(r"\*\*(.+?)\*\*", text, flags=re.S)
    return [" ".join(h.replace("`", "").split()).lower() for h in heads]


POINTERS = _pointers()


def test_the_code_points_to_the_docs():
    assert len(POINTERS) > 100          # the scan finds the pointers it is meant to check


@pytest.mark.parametrize(("where", "page", "section"), POINTERS,
                         ids=[f"{w}->{p}:{s}" for w, p, s in POINTERS])
def test_a_pointer_lands_on_a_page_and_its_heading(where, page, section):
    target = ROOT / page
    if page == "docs/page.md":          # the page a study publishes to, named in prose
        return
    assert target.is_file(), f"{where} points to {page}, which does not exist"
    if section is not None:
        want = section.replace("`", "").rstrip(".").lower()
        assert any(want in h for h in _headings(target)), \
            f"{where} points to {page}, \"{section}\": no heading or bold label of the page"
