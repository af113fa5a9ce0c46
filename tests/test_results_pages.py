"""A benchmark rewrites only the marked block of its results page (benchmarks/pages.py): the
hand-written narrative before and after it stays as it was, to the byte."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import pages
from benchmarks.pages import BEGIN, END, with_block, write_block

NARRATIVE_ABOVE = "# A page\n\nWritten by hand: what the run shows.\n"
NARRATIVE_BELOW = "\n## Context\n\nAlso by hand, with a table of its own:\n\n| a |\n|---|\n| 1 |\n"


def test_only_the_marked_block_is_replaced(tmp_path):
    page = tmp_path / "bench.md"
    page.write_text(f"{NARRATIVE_ABOVE}\n{BEGIN}\n| old | table |\n|---|---|\n{END}\n{NARRATIVE_BELOW}")
    write_block(page, "# Generated\n\n| new | table |\n|---|---|\n")
    block = f"{BEGIN}\n# Generated\n\n| new | table |\n|---|---|\n{END}\n"
    assert page.read_text() == f"{NARRATIVE_ABOVE}\n{block}{NARRATIVE_BELOW}"
    write_block(page, "# Generated\n\n| newer |\n")  # a second run: still one block, narrative kept
    again = page.read_text()
    assert again.startswith(f"{NARRATIVE_ABOVE}\n{BEGIN}\n# Generated\n\n| newer |\n{END}\n")
    assert again.endswith(NARRATIVE_BELOW) and again.count(BEGIN) == again.count(END) == 1


def test_a_new_page_is_the_block_and_a_page_without_one_gets_it_appended(tmp_path):
    new = tmp_path / "results" / "new.md"
    write_block(new, "table\n")
    assert new.read_text() == f"{BEGIN}\ntable\n{END}\n"
    hand = tmp_path / "hand.md"
    hand.write_text(NARRATIVE_ABOVE)
    write_block(hand, "table\n")
    assert hand.read_text() == f"{NARRATIVE_ABOVE}\n{BEGIN}\ntable\n{END}\n"


@pytest.mark.parametrize(
    "page", [f"{BEGIN}\nx\n", f"x\n{END}\n", f"{END}\n{BEGIN}\n", f"{BEGIN}\n{END}\n{BEGIN}\n{END}\n"]
)
def test_broken_markers_leave_the_page_untouched(tmp_path, page):
    path = tmp_path / "broken.md"
    path.write_text(page)
    with pytest.raises(ValueError):
        write_block(path, "table\n")
    assert path.read_text() == page
    with pytest.raises(ValueError):
        with_block(page, "table\n")


def test_write_page_keeps_the_narrative(tmp_path, monkeypatch, capsys):
    from benchmarks import report

    monkeypatch.setattr(report, "RESULTS", tmp_path)
    (tmp_path / "bench.md").write_text(f"{NARRATIVE_ABOVE}\n{BEGIN}\nold\n{END}\n{NARRATIVE_BELOW}")
    report.write_page("bench.md", "new\n")
    assert (tmp_path / "bench.md").read_text() == f"{NARRATIVE_ABOVE}\n{BEGIN}\nnew\n{END}\n{NARRATIVE_BELOW}"


#: Pages no benchmark writes: all hand-written.
HAND_WRITTEN = {"examples.md", "global_choose.md"}


def test_every_page_a_benchmark_writes_has_one_block():
    results = Path(pages.__file__).parent / "results"
    names = sorted(path.name for path in results.glob("*.md"))
    assert "adversarial.md" in names and "peers.md" in names
    for name in names:
        text = (results / name).read_text()
        if name in HAND_WRITTEN:
            assert BEGIN not in text and END not in text, name
        else:
            assert with_block(text, "x")[1], name
