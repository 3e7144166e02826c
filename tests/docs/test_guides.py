"""Every task guide's code runs, and prints what the page says it prints.

A guide is a Markdown page in ``docs/guides/`` (``index.md`` aside). Its ```` ```python ````
blocks run in order, in one namespace per page, in a temporary working directory. A
```` ```text ```` block right after a python block (blank lines between allowed) is that
block's expected output: the test compares it with what the block printed (trailing spaces
ignored). A block of another language whose info string names a file after the language
(```` ```c host.c ````) is written to that file before the python blocks that follow it run
(a guide's C source, a TOML file). A page that needs a C compiler says so with the comment
``<!-- guide-requires: c-compiler -->`` and is skipped, with the reason, where there is none.
A page whose code raises one of the package's warnings on purpose (an input outside a model's
calibrated range, a parameter the data hardly determine) declares it, category and the start of
the message, in a comment ``<!-- guide-warns: AlteredResultWarning: initial_speed = 44.44 m/s
-->``: the page must then raise it, and any other warning of the package is still an error.
After a change that alters the output on purpose, rewrite the text blocks with
``RAILADHESION_UPDATE_GUIDES=1 python3 -m pytest tests/docs/test_guides.py`` and review the
diff. See docs/contributing-docs.md.
"""

import contextlib
import io
import os
import re
import warnings
from pathlib import Path

import pytest

GUIDES = Path(__file__).resolve().parents[2] / "docs" / "guides"
FENCE = re.compile(r"^```(\w*)([^\n]*)\n(.*?)^```[ \t]*$", re.M | re.S)
FILE_NAME = re.compile(r"^[\w.-]+\.\w+$")
REQUIRES_C = "<!-- guide-requires: c-compiler -->"
WARNS = re.compile(r"<!-- guide-warns: (\w+): (.*?)\s*-->", re.S)
UPDATE = os.environ.get("RAILADHESION_UPDATE_GUIDES") == "1"


def blocks(text: str):
    """[(code, expected output or None, (start, end) of the output block's body, files)] of
    the python blocks; ``files`` are the (name, content) of the file blocks before the python
    block (since the previous one)."""
    fences = list(FENCE.finditer(text))
    out, files = [], []
    for i, fence in enumerate(fences):
        lang, info, body = fence.group(1), fence.group(2).strip(), fence.group(3)
        if lang not in ("python", "text") and FILE_NAME.match(info):
            files.append((info, body))
            continue
        if lang != "python":
            continue
        expected, span = None, None
        if i + 1 < len(fences):
            nxt = fences[i + 1]
            between = text[fence.end():nxt.start()]
            if nxt.group(1) == "text" and not between.strip():
                expected, span = nxt.group(3), nxt.span(3)
        out.append((body, expected, span, files))
        files = []
    return out


def _clean(text: str) -> str:
    return "\n".join(line.rstrip() for line in text.strip("\n").splitlines())


PAGES = sorted(p for p in GUIDES.glob("*.md") if p.name != "index.md")


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_guide_runs_and_prints_what_it_shows(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    text = page.read_text(encoding="utf-8")
    if REQUIRES_C in text:
        from railadhesion.export.native import find_c_compiler

        if find_c_compiler() is None:
            pytest.skip(f"{page.name} needs a C compiler (set CC, or install gcc or clang)")
    found = blocks(text)
    assert found, f"{page.name} has no python block"
    namespace = {"__name__": f"guide_{page.stem}"}
    replacements = []
    declared = [(getattr(_warning_classes(), category), " ".join(start.split()))
                for category, start in WARNS.findall(text)]
    with warnings.catch_warnings(record=True) as caught:
        for category, start in declared:  # recorded, not errors (the pyproject's filter)
            warnings.filterwarnings("always", message=re.escape(start), category=category)
        _run_blocks(page, found, namespace, replacements, tmp_path)
    for category, start in declared:
        assert any(issubclass(w.category, category) and str(w.message).startswith(start)
                   for w in caught), f"{page.name} declares a warning it does not raise: {start}"
    if UPDATE and replacements:
        for (start, end), output in sorted(replacements, reverse=True):
            text = text[:start] + output.rstrip("\n") + "\n" + text[end:]
        page.write_text(text, encoding="utf-8")


def _warning_classes():
    """A namespace of the package's warning classes, by name."""
    import types

    from railadhesion import plausibility
    from railadhesion.calibration import checks

    return types.SimpleNamespace(**{**vars(plausibility), **{
        k: v for k, v in vars(checks).items() if k.endswith("Warning")}})


def _run_blocks(page, found, namespace, replacements, tmp_path):
    """Run a page's python blocks in order, comparing (or, updating, collecting) outputs."""
    for n, (code, expected, span, files) in enumerate(found, start=1):
        for name, content in files:
            (tmp_path / name).write_text(content, encoding="utf-8")
        stdout = io.StringIO()
        with contextlib.redirect_stdout(stdout):
            exec(compile(code, f"{page.name}, python block {n}", "exec"), namespace)
        if expected is None:
            continue
        if UPDATE:
            printed = "\n".join(line.rstrip() for line in stdout.getvalue().splitlines())
            replacements.append((span, printed))
            continue
        assert _clean(stdout.getvalue()) == _clean(expected), (
            f"{page.name}, python block {n}: the output differs from the page's text block")


def test_the_parser_pairs_code_and_output():
    text = "```python\nprint(1)\n```\n\n```text\n1\n```\n```python\nx = 2\n```\n```bash\nls\n```\n"
    (code1, out1, _, _), (code2, out2, _, _) = blocks(text)
    assert (code1, out1) == ("print(1)\n", "1\n")
    assert (code2, out2) == ("x = 2\n", None)


def test_file_blocks_are_written_before_the_python_blocks_that_follow():
    text = ("```c host.c\nint main(void) { return 0; }\n```\n"
            "```toml\nnot = 'a file'\n```\n"
            "```python\nprint(open('host.c').read())\n```\n"
            "```python\nx = 1\n```\n")
    (_, _, _, files1), (_, _, _, files2) = blocks(text)
    assert files1 == [("host.c", "int main(void) { return 0; }\n")]
    assert files2 == []
