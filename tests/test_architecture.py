"""The package's import rules (docs/architecture.md), read from the source with ``ast``.

1. No import circles between modules, counting the imports inside functions.
2. No private name (``_x``) imported from another module, and no private module imported from
   outside the package that holds it.
3. Layers: a module imports only from its own top-level unit or from a lower floor of
   :data:`FLOORS` (the ground floor's modules may also import each other); every top-level
   unit has a floor.

Violations that other branches are removing are listed in :data:`PENDING`, with who removes
them: they are tolerated by the rule tests and expected to vanish. While :data:`PENDING` has
entries, mark :func:`test_pending_violations_are_gone` as a strict xfail; when it passes,
delete the entries it no longer finds and the mark (it is empty today: the test must pass).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PACKAGE = "railadhesion"

#: Floors from the ground up: a top-level unit (a subpackage or a module of the package; ``""``
#: is the package's ``__init__``) imports only from its own unit or from lower floors.
FLOORS: tuple[tuple[str, ...], ...] = (
    ("_validate", "_docstrings", "_labelled", "_jit", "plausibility", "numerics", "simd"),
    ("contact",),
    ("models",),
    ("", "io"),
    ("calibration", "braking"),
    ("identification",),
    ("monitor",),
    ("plotting", "export", "sweeps"),
    ("demo", "cli_checks"),
    ("cli_braking", "cli_export", "cli_identification", "cli_sweeps", "cli_wsp",
     "cli_odometry", "cli_monitor"),
    ("cli",),
    ("__main__",),
)

#: Violations being removed on other branches: (rule, importer, imported, name) -> owner.
#: Empty: keep it so while nothing is in flight (see test_pending_violations_are_gone).
PENDING: dict[tuple[str, str, str, str], str] = {}


# --- reading the imports ------------------------------------------------------------------


def find_modules(src: Path, package: str) -> dict[str, Path]:
    """Module name -> file, for every ``.py`` file of the package (``__init__`` files give
    the package's name)."""
    out = {}
    for path in sorted((src / package).rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _absolute(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ""
    base = module.split(".")
    if not is_package:
        base.pop()
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def read_imports(modules: dict[str, Path], package: str):
    """Every import of a module of the package by another, wherever it stands (module level,
    functions, ``if TYPE_CHECKING``): tuples (importer, imported module, name or "", line).
    ``from a import b`` with ``a.b`` a module counts as an import of ``a.b``."""
    found = []
    for module, path in modules.items():
        is_package = path.name == "__init__.py"
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name.split(".")[0] == package:
                        found.append((module, alias.name, "", node.lineno))
            elif isinstance(node, ast.ImportFrom):
                target = _absolute(module, is_package, node)
                if target.split(".")[0] != package:
                    continue
                for alias in node.names:
                    sub = f"{target}.{alias.name}"
                    if sub in modules:
                        found.append((module, sub, "", node.lineno))
                    else:
                        found.append((module, target, alias.name, node.lineno))
    return [imp for imp in found if imp[1] != imp[0]]


def circles(modules, imports) -> list[set[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for importer, target, _, _ in imports:
        if target in graph:
            graph[importer].add(target)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    comp = set()
                    while True:
                        top = stack.pop()
                        on_stack.discard(top)
                        comp.add(top)
                        if top == node:
                            break
                    if len(comp) > 1:
                        out.append(comp)
            elif child not in index:
                index[child] = low[child] = len(index)
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph[child]))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])
    return out


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def unit(module: str) -> str:
    """Top-level unit of a module: ``railadhesion.models.polach`` -> ``models``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def violations(src: Path = SRC, package: str = PACKAGE, floors=FLOORS):
    """Every breach of the three rules, as (rule, importer, imported, name) -> line."""
    modules = find_modules(src, package)
    imports = read_imports(modules, package)
    found: dict[tuple[str, str, str, str], int] = {}
    for comp in circles(modules, imports):
        for importer, target, _, line in imports:
            if importer in comp and target in comp:
                found.setdefault(("circle", importer, target, ""), line)
    floor_of = {u: k for k, row in enumerate(floors) for u in row}
    for importer, target, name, line in imports:
        if name and _private(name):
            found.setdefault(("private", importer, target, name), line)
        parent, _, last = target.rpartition(".")
        if _private(last) and not (importer + ".").startswith(parent + "."):
            found.setdefault(("private", importer, target, ""), line)
        a, b = unit(importer), unit(target)
        fa, fb = floor_of.get(a, -1), floor_of.get(b, -1)
        if a != b and (fb > fa or fb == fa > 0):  # the ground floor's modules may share
            found.setdefault(("layer", importer, target, ""), line)
    for module in modules:
        if unit(module) not in floor_of:
            found.setdefault(("no floor", module, "", ""), 0)
    return found


def _show(items) -> str:
    return "\n".join(f"  {rule}: {imp} -> {tgt}{'.' + n if n else ''} (line {line})"
                     for (rule, imp, tgt, n), line in sorted(items))


# --- the rules ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def found():
    return violations()


@pytest.mark.parametrize("rule", ["circle", "private", "layer", "no floor"])
def test_no_violation_beyond_the_pending_ones(found, rule):
    new = {k: v for k, v in found.items() if k[0] == rule and k not in PENDING}
    assert not new, f"{rule} violations (docs/architecture.md):\n{_show(new.items())}"


def test_pending_violations_are_gone(found):
    left = {k: found[k] for k in PENDING if k in found}
    assert not left, "still there:\n" + _show(left.items())


def test_the_floors_are_those_of_the_architecture_page():
    # the table of docs/architecture.md lists the same floors, ground floor first
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| (\d+) \| ([^|]+) \|", text, flags=re.MULTILINE)
    assert [int(k) for k, _ in rows] == list(range(len(FLOORS)))
    for (_, cell), row in zip(rows, FLOORS, strict=True):
        names = {n.strip("`/ ").removesuffix(".py") for n in cell.split(",")}
        names = {"" if n == "__init__" else n for n in names}
        assert names == set(row), (cell, row)


# --- the checker itself -------------------------------------------------------------------


def _tree(tmp_path: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = tmp_path / "src" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return tmp_path / "src"


def test_the_checker_finds_each_kind_of_violation(tmp_path):
    src = _tree(tmp_path, {
        "pkg/__init__.py": "",
        "pkg/low/__init__.py": "",
        "pkg/low/a.py": "def f():\n    from pkg.low import b  # inside a function\n",
        "pkg/low/b.py": "from .a import f\nfrom pkg.low._c import g\n",
        "pkg/low/_c.py": "def g():\n    pass\n",
        "pkg/high.py": "import pkg.low.a\nfrom pkg.low.b import _hidden\nfrom pkg.low import _c\n",
        "pkg/stray.py": "",
    })
    found = violations(src, "pkg", (("low",), ("high",)))
    assert set(found) == {
        ("circle", "pkg.low.a", "pkg.low.b", ""),
        ("circle", "pkg.low.b", "pkg.low.a", ""),
        ("private", "pkg.high", "pkg.low.b", "_hidden"),
        ("private", "pkg.high", "pkg.low._c", ""),
        ("no floor", "pkg.stray", "", ""),
        ("no floor", "pkg", "", ""),
    }
    # the same tree read upside down: every import of high from low is upward
    found = violations(src, "pkg", (("high", "stray", ""), ("low",)))
    assert {k for k in found if k[0] == "layer"} == {
        ("layer", "pkg.high", "pkg.low.a", ""),
        ("layer", "pkg.high", "pkg.low.b", ""),
        ("layer", "pkg.high", "pkg.low._c", ""),
    }
    # side by side: allowed on the ground floor only
    for floors, expected in (((("high", "low", "stray", ""),), set()),
                             (((), ("high", "low", "stray", "")), {"pkg.low.a", "pkg.low.b",
                                                                    "pkg.low._c"})):
        found = violations(src, "pkg", floors)
        assert {k[2] for k in found if k[0] == "layer"} == expected


def test_the_package_is_read_whole():
    modules = find_modules(SRC, PACKAGE)
    assert {"railadhesion", "railadhesion.models.polach", "railadhesion.cli"} <= set(modules)
    imports = read_imports(modules, PACKAGE)
    # a function-level import is seen (cli imports the identification pipeline in a command)
    assert any(i == "railadhesion.cli_identification" and t.startswith(
        "railadhesion.identification") for i, t, _, _ in imports)


# --- numba's private internals: in _jit.py only ---------------------------------------------

#: numba modules that are not its public API (numba.extending, numba.types, numba.typed and
#: the top-level names are).
NUMBA_PRIVATE_MODULES = ("numba.core", "numba.np", "numba.cpython", "numba.misc",
                         "numba.parfors", "numba.typeconv", "numba.cuda.cudadrv")
#: Dispatcher attributes that are numba internals (its public ones: py_func, signatures,
#: compile, recompile, inspect_*, stats).
NUMBA_PRIVATE_ATTRIBUTES = {"overloads", "entry_point", "_cache_path", "disable_compile",
                            "targetctx", "typingctx", "_compile_for_args", "_can_compile",
                            "_cache"}


def numba_internals(src: Path = SRC, package: str = PACKAGE, allowed=("railadhesion._jit",)):
    """Uses of numba's private modules and dispatcher internals outside ``allowed``:
    (module, what, line). ``self._cache`` of the package's own classes is not numba's."""
    found = []
    for module, path in find_modules(src, package).items():
        if module in allowed:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level:
                names = [node.module or ""]
            for name in names:
                if name.startswith(NUMBA_PRIVATE_MODULES):
                    found.append((module, name, node.lineno))
            if (isinstance(node, ast.Attribute) and node.attr in NUMBA_PRIVATE_ATTRIBUTES
                    and not (isinstance(node.value, ast.Name) and node.value.id == "self")):
                found.append((module, node.attr, node.lineno))
    return found


def test_numba_internals_are_used_in_jit_only():
    assert not numba_internals(), numba_internals()


def test_the_numba_check_finds_internals(tmp_path):
    src = _tree(tmp_path, {
        "pkg/__init__.py": "",
        "pkg/a.py": "from numba.core import types\nimport numba.np.numpy_support\n",
        "pkg/b.py": "def f(d):\n    return d.overloads[0].entry_point, d._cache._cache_path\n",
        "pkg/c.py": "class C:\n    def f(self):\n        return self._cache\n",
        "pkg/_jit.py": "def g(d):\n    return d.overloads\n",
    })
    found = {(m, what) for m, what, _ in numba_internals(src, "pkg", ("pkg._jit",))}
    assert found == {("pkg.a", "numba.core"), ("pkg.a", "numba.np.numpy_support"),
                     ("pkg.b", "overloads"), ("pkg.b", "entry_point"), ("pkg.b", "_cache"),
                     ("pkg.b", "_cache_path")}


# --- the table of the laws ------------------------------------------------------------------


def law_table(text: str) -> list[tuple[str, list[str], list[str]]]:
    """Rows of the tables of "Where each law lives": (law, files, function names)."""
    part = text[text.index("## Where each law lives"):text.index("## How a kernel is added")]
    rows = []
    for line in part.splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
        if len(cells) != 3 or cells[0] in ("Law (source)", "---"):
            continue
        files = re.findall(r"`([\w/]+\.py)`", cells[1])
        names = re.findall(r"`([\w.]+)`", cells[2])  # Class.method: the method
        rows.append((cells[0], files, [n.split(".")[-1] for n in names]))
    return rows


def test_every_law_of_the_table_is_where_it_says():
    rows = law_table((ROOT / "docs" / "architecture.md").read_text(encoding="utf-8"))
    assert len(rows) >= 20
    missing = []
    for law, files, names in rows:
        assert files, law
        text = "\n".join((SRC / PACKAGE / f).read_text(encoding="utf-8") for f in files)
        defined = {n.name for n in ast.walk(ast.parse(text))
                   if isinstance(n, ast.FunctionDef | ast.ClassDef)}
        defined |= {t.id for n in ast.walk(ast.parse(text)) if isinstance(n, ast.Assign)
                    for t in n.targets if isinstance(t, ast.Name)}
        missing += [(law, name) for name in names if name not in defined]
    assert not missing, missing
