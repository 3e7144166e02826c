"""The API reference (docs/api/*.rst) documents every public name, and only public names.

Public names are the ``__all__`` of the top-level package, of every subpackage, of every
top-level module that has one (``railadhesion.plotting``, ``railadhesion.plausibility``) and of
``railadhesion.models.kernels``. Each namespace has its page ``docs/api/<name>.rst``
(``toplevel.rst`` for the package itself), where every name of its ``__all__`` appears as an
``autosummary`` entry or as a ``:func:``/``:class:``/``:data:``/``:obj:`` reference to the
same object. These tests read the pages' source: no Sphinx needed. The Sphinx build (CI:
``.ci/run``) then checks that every entry resolves (``-n -W``).
"""

import importlib
import pkgutil
import re
from pathlib import Path

import pytest

import railadhesion

API = Path(__file__).resolve().parents[2] / "docs" / "api"

# namespaces below the subpackages whose __all__ is public API of its own
EXTRA_NAMESPACES = {"railadhesion.models.kernels": "kernels"}


def public_namespaces():
    """{module name: page stem} of every namespace whose __all__ the reference documents."""
    spaces = {"railadhesion": "toplevel"}
    for info in pkgutil.iter_modules(railadhesion.__path__, "railadhesion."):
        short = info.name.rsplit(".", 1)[1]
        if short.startswith("_"):
            continue
        module = importlib.import_module(info.name)
        if info.ispkg or hasattr(module, "__all__"):
            spaces[info.name] = short
    spaces.update(EXTRA_NAMESPACES)
    return spaces


def resolve(path):
    """The object at a dotted path, as attribute access sees it (a package's function named
    like its submodule is the function), or None."""
    parts = path.split(".")
    if parts[0] != "railadhesion":
        return None
    obj = railadhesion
    for i, part in enumerate(parts[1:], start=2):
        if hasattr(obj, part):
            obj = getattr(obj, part)
            continue
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            return None
    return obj


def documented_entries(page: Path):
    """[(full name, kind)] on one page: autosummary entries and Python roles."""
    entries = []
    module = None
    in_autosummary = False
    for line in page.read_text(encoding="utf-8").splitlines():
        directive = re.match(r"\.\. (currentmodule|module|automodule)::\s*(\S+)", line)
        if directive:
            module = directive.group(2)
        if line.startswith(".. autosummary::"):
            in_autosummary = True
            continue
        if in_autosummary:
            if line and not line.startswith(" "):
                in_autosummary = False
            elif line.strip() and not line.strip().startswith(":"):
                entries.append((f"{module}.{line.strip()}", "autosummary"))
                continue
        for target in re.findall(r":(?:func|class|data|obj|exc|meth):`~?([\w.]+)`", line):
            if not target.startswith("railadhesion") and module:
                target = f"{module}.{target}"
            entries.append((target, "role"))
    return entries


SPACES = public_namespaces()


def test_every_namespace_has_a_page_in_the_api_index():
    index = (API / "index.rst").read_text(encoding="utf-8")
    missing = [f"docs/api/{page}.rst ({name})" for name, page in SPACES.items()
               if not (API / f"{page}.rst").exists()]
    assert not missing, f"public namespaces without an API page: {missing}"
    toc = re.findall(r"^   (\S+)$", index, flags=re.M)
    unlisted = [page for page in SPACES.values() if page not in toc]
    assert not unlisted, f"add these pages to the toctree of docs/api/index.rst: {unlisted}"


@pytest.mark.parametrize("namespace", sorted(SPACES))
def test_every_public_name_is_documented_on_its_page(namespace):
    module = importlib.import_module(namespace)
    page = API / f"{SPACES[namespace]}.rst"
    names = list(module.__all__)
    entries = documented_entries(page)
    by_name = {name for name, _ in entries}
    objects = [resolve(name) for name, _ in entries]
    missing = []
    for name in names:
        obj = getattr(module, name)
        if f"{namespace}.{name}" in by_name:
            continue
        if callable(obj) and any(o is obj for o in objects):
            continue  # documented under another public path, linked from this page
        missing.append(name)
    assert not missing, (
        f"{namespace}.__all__ names missing from docs/api/{page.name} "
        f"(add each as an autosummary entry in the right group): {missing}")


@pytest.mark.parametrize("namespace", sorted(SPACES))
def test_no_page_documents_a_name_that_is_not_public(namespace):
    module = importlib.import_module(namespace)
    page = API / f"{SPACES[namespace]}.rst"
    public = {id(getattr(module, n)) for n in module.__all__}
    stale = []
    for name, kind in documented_entries(page):
        if kind != "autosummary":
            continue
        obj = resolve(name)
        if obj is None:
            stale.append(f"{name} (does not exist)")
        elif name.rsplit(".", 1)[1] not in module.__all__ and id(obj) not in public:
            stale.append(f"{name} (not in {namespace}.__all__)")
    assert not stale, f"docs/api/{page.name} documents names that are not public: {stale}"


def test_the_tests_can_fail(tmp_path):
    """A page without an entry for a name is reported (guards the parser above)."""
    page = tmp_path / "p.rst"
    page.write_text(".. currentmodule:: railadhesion.io\n\n.. autosummary::\n   :toctree: x/\n\n"
                    "   read_creep_curve\n\nText :func:`railadhesion.contact.hertz_3d`.\n")
    names = {n for n, _ in documented_entries(page)}
    assert names == {"railadhesion.io.read_creep_curve", "railadhesion.contact.hertz_3d"}
