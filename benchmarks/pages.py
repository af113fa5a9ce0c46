"""Results pages whose generated part is a marked block: a benchmark rewrites only the block.

A page in ``benchmarks/results/`` may hold hand-written narrative (context, comparisons with
earlier runs, what a figure means) beside the tables a benchmark prints. The benchmark writes
its text between the two marker lines :data:`BEGIN` and :data:`END` and leaves every other
line of the page as it is:

* no page yet: the page is the marked block alone;
* a page with one block: the block's lines are replaced;
* a page without a block (a hand-written page): the block is appended at its end, nothing
  removed, and a note says so (move the block where it belongs);
* a page whose markers are not one BEGIN followed by one END: :class:`ValueError`, the page
  untouched.
"""

from __future__ import annotations

from pathlib import Path

BEGIN = "<!-- generated: begin -->"
END = "<!-- generated: end -->"


def _marker_lines(lines: list[str], path: Path) -> tuple[int, int] | None:
    """The indices of the BEGIN and END lines, or None if the page has neither."""
    begins = [i for i, line in enumerate(lines) if line.strip() == BEGIN]
    ends = [i for i, line in enumerate(lines) if line.strip() == END]
    if not begins and not ends:
        return None
    if len(begins) != 1 or len(ends) != 1 or begins[0] > ends[0]:
        raise ValueError(f"{path}: expected one '{BEGIN}' line before one '{END}' line")
    return begins[0], ends[0]


def with_block(page: str, text: str, path: Path = Path("page")) -> tuple[str, bool]:
    """``page`` with its marked block's content replaced by ``text``; and whether it had a block
    (without one, the block is appended)."""
    block = [BEGIN, *text.rstrip("\n").split("\n"), END]
    lines = page.split("\n")
    found = _marker_lines(lines, path)
    if found is None:
        kept = page.rstrip("\n")
        return (kept + "\n\n" if kept else "") + "\n".join(block) + "\n", False
    begin, end = found
    return "\n".join([*lines[:begin], *block, *lines[end + 1 :]]), True


def write_block(path: Path, text: str) -> Path:
    """Write ``text`` as the generated block of the page at ``path`` (see the module's doc)."""
    path = Path(path)
    page = path.read_text() if path.exists() else ""
    new, had_block = with_block(page, text, path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(new)
    if page and not had_block:
        print(f"note: {path} had no generated block: appended one at its end, nothing removed")
    return path
