"""Every page in docs/ is reachable from the site's index through the toctrees.

Sphinx warns about a page in no toctree (and CI's build fails on it); this test says the same
without Sphinx, in the test suite, naming the pages. Top-level pages are taken by the glob of
docs/index.md; a page in a folder needs a toctree line (docs/contributing-docs.md).
"""

import posixpath
import re
from pathlib import Path

DOCS = Path(__file__).resolve().parents[2] / "docs"
SKIP = ("_build/", "_ext/", "_templates/", "auto_examples/", "api/generated/")
TOCTREE_MD = re.compile(r"^```\{toctree\}[^\n]*\n(.*?)^```", re.S | re.M)
TOCTREE_RST = re.compile(r"^\.\. toctree::[^\n]*\n((?:[ \t]+[^\n]*\n|[ \t]*\n)*)", re.M)


def sources():
    """{docname: path} of every page (Markdown and reStructuredText) of the site."""
    pages = {}
    for path in [*DOCS.rglob("*.md"), *DOCS.rglob("*.rst")]:
        rel = path.relative_to(DOCS).as_posix()
        if rel.startswith(SKIP) or rel == "sg_execution_times.rst":
            continue
        pages[rel.rsplit(".", 1)[0]] = path
    return pages


def toctree_entries(path: Path):
    """[(entry, glob)] of every toctree of a page."""
    entries = []
    pattern = TOCTREE_MD if path.suffix == ".md" else TOCTREE_RST
    for block in pattern.findall(path.read_text(encoding="utf-8")):
        is_glob = ":glob:" in block
        for line in block.splitlines():
            line = line.strip()
            if line and not line.startswith(":"):
                entries.append((line, is_glob))
    return entries


def _glob(pattern: str):
    """Sphinx's toctree glob: ``*`` and ``?`` do not cross a ``/``."""
    return re.compile(re.escape(pattern).replace(r"\*", "[^/]*").replace(r"\?", "[^/]"))


def reachable(pages):
    seen, todo = {"index"}, ["index"]
    while todo:
        doc = todo.pop()
        if doc not in pages:
            continue  # generated (the gallery's index)
        base = posixpath.dirname(doc)
        for entry, is_glob in toctree_entries(pages[doc]):
            target = posixpath.normpath(posixpath.join(base, entry))
            names = [target]
            if is_glob and any(c in entry for c in "*?["):
                names = [n for n in pages if _glob(target).fullmatch(n) and n != doc]
            for name in names:
                if name not in seen:
                    seen.add(name)
                    todo.append(name)
    return seen


def test_every_page_is_in_a_toctree():
    pages = sources()
    missing = sorted(set(pages) - reachable(pages))
    assert not missing, (
        f"pages in no toctree (add a line to the toctree of their folder's index): {missing}")


def test_a_page_outside_every_toctree_is_found(tmp_path):
    (tmp_path / "index.md").write_text("```{toctree}\n:glob:\n\n*\n```\n", encoding="utf-8")
    (tmp_path / "top.md").write_text("# top\n", encoding="utf-8")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "lost.md").write_text("# lost\n", encoding="utf-8")
    pages = {p.relative_to(tmp_path).as_posix()[:-3]: p for p in tmp_path.rglob("*.md")}
    assert set(pages) - reachable(pages) == {"sub/lost"}
