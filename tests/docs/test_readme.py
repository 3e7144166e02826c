"""The README stays a short entry point (issue 24): at most 150 lines, the two set-up commands
unchanged, and every relative link pointing at a file of the repository. Its tour is a doctest
(pyproject.toml: --doctest-glob=README.md)."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")

COMMANDS = (
    'python3 -m pip install -e ".[dev]" && python3 -m railadhesion demo',
    'python3 -m pip install -e ".[dev]" && python3 -m pytest -q -n auto',
)


def test_readme_is_short():
    assert len(README.splitlines()) <= 150


def test_readme_keeps_the_two_commands():
    for command in COMMANDS:
        assert command in README


def test_readme_says_how_to_build_the_docs_in_one_command():
    assert 'python3 -m pip install -e ".[docs]" && python3 -m sphinx' in README


def test_relative_links_of_the_readme_exist():
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", README)
    local = [link for link in links if "://" not in link]
    assert local, "the README links into the documentation"
    missing = [link for link in local if not (ROOT / link).exists()]
    assert not missing, f"README links to files that do not exist: {missing}"
