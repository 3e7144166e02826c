"""Sphinx helpers of the railadhesion documentation (local extension, docs only).

* ``|x|`` in docstrings means an absolute value, not a reStructuredText substitution: the
  bars are escaped before the docstrings are parsed (outside literals and code).
* A cross-reference to where an object is *defined* (``railadhesion.models.polach.
  polach_forces``) is resolved to where it is *documented* (``railadhesion.models.
  polach_forces``), by object identity. A reference to an object of the package that the API
  reference does not document (a private helper) is shown as plain text. A reference to a
  name that does not exist stays a warning: with ``-n -W`` it fails the build.
* ``.. railadhesion-cli::`` writes the ``--help`` text of every command of the CLI.
"""

from __future__ import annotations

import importlib
import re
import sys

from docutils import nodes
from docutils.parsers.rst import Directive
from sphinx.util.nodes import make_refnode

_LITERAL = re.compile(r"(``.+?``)")


def _escape_bars(text: str) -> str:
    parts = _LITERAL.split(text)
    return "".join(p if p.startswith("``") else p.replace("|", r"\|") for p in parts)


def escape_absolute_values(app, what, name, obj, options, lines):
    """Escape ``|`` outside inline literals, doctest blocks and literal blocks."""
    in_doctest = False
    literal_indent = None  # indentation of the paragraph that ended with "::"
    pending_literal, pending_indent = False, 0
    for i, line in enumerate(lines):
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                continue
        if pending_literal and stripped:
            pending_literal = False
            if indent > pending_indent:
                literal_indent = pending_indent
                continue
        if stripped.startswith(">>>"):
            in_doctest = True
        if in_doctest:
            if not stripped:
                in_doctest = False
            continue
        if stripped.endswith("::"):
            pending_literal, pending_indent = True, indent
        lines[i] = _escape_bars(line)


_FIELD = object()  # stands for a dataclass field


def _import_path(path: str):
    """The object at a dotted path as attribute access sees it, or None."""
    parts = path.split(".")
    if parts[0] != "railadhesion":
        return None
    obj = importlib.import_module("railadhesion")
    for i, part in enumerate(parts[1:], start=2):
        if hasattr(obj, part):
            obj = getattr(obj, part)
            continue
        fields = getattr(obj, "__dataclass_fields__", {}) if isinstance(obj, type) else {}
        if part in fields and i == len(parts):
            return _FIELD  # a dataclass field without a default: not a class attribute
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            return None
    return obj


def _documented(env):
    """id(object) -> (name, entry) of every Python object the site documents."""
    cache = getattr(env, "_railadhesion_documented", None)
    if cache is None or cache[0] != len(env.domains["py"].objects):
        table = {}
        for name, entry in env.domains["py"].objects.items():
            obj = _import_path(name)
            if obj is not None and not isinstance(obj, (int, float, str, bool)):
                table.setdefault(id(obj), (name, entry, obj))
        cache = (len(env.domains["py"].objects), table)
        env._railadhesion_documented = cache
    return cache[1]


def resolve_definition_paths(app, env, node, contnode):
    if node.get("refdomain") != "py":
        return None
    target = re.sub(r"\s+", "", node["reftarget"]).lstrip(".~")
    module, cls = node.get("py:module"), node.get("py:class")
    candidates = [target]
    if cls and module:
        candidates.append(f"{module}.{cls}.{target}")
    if module:
        candidates.append(f"{module}.{target}")
    # a docstring names objects of the module that defines it: "docstring of a.b.c.Name"
    source = node.source or ""
    where = re.search(r"docstring of ([\w.]+)", source)
    if where:
        parts = where.group(1).split(".")
        candidates += [".".join([*parts[:i], target]) for i in range(len(parts), 0, -1)]
    # and, in a summary table, those of the submodules of the current package
    if module:
        candidates += [f"{name}.{target}" for name in sorted(sys.modules)
                       if name.startswith(module + ".")]
    for candidate in candidates:
        obj = _import_path(candidate)
        if obj is None:
            continue
        found = _documented(env).get(id(obj))
        if found is not None and found[2] is obj:
            name, entry, _ = found
            return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id,
                                contnode, name)
        return contnode  # exists in the package, not in the API reference: plain text
    if module:
        # a method named in a summary table (no class context): a documented class's member
        objects = env.domains["py"].objects
        matches = [name for name in objects
                   if name.startswith(module + ".") and name.endswith("." + target)]
        if len(matches) == 1:
            entry = objects[matches[0]]
            return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id,
                                contnode, matches[0])
        head = target.split(".")[0]
        for name, entry in objects.items():
            if entry.objtype == "class" and name.startswith(module + "."):
                cls_obj = _import_path(name)
                if cls_obj is not None and hasattr(cls_obj, head):
                    return contnode
    return None


def _help_sections(command, path, state):
    from typer.testing import CliRunner

    from railadhesion.cli import app as cli_app

    result = CliRunner().invoke(cli_app, [*path, "--help"], prog_name="railadhesion",
                                env={"COLUMNS": "96", "NO_COLOR": "1", "TERM": "dumb"},
                                terminal_width=96)
    if result.exit_code != 0:
        raise RuntimeError(f"railadhesion {' '.join(path)} --help failed: {result.output}")
    title = " ".join(["railadhesion", *path])
    section = nodes.section(ids=[nodes.make_id("cli " + title)])
    section += nodes.title(text=title)
    section += nodes.literal_block(result.output, result.output)
    sections = [section]
    for name, sub in getattr(command, "commands", {}).items():
        if getattr(sub, "hidden", False):
            continue
        sections += _help_sections(sub, [*path, name], state)
    return sections


class CliHelp(Directive):
    """Every command's ``--help`` text, one section per command, in registration order."""

    has_content = False

    def run(self):
        import typer.main

        from railadhesion.cli import app as cli_app

        root = typer.main.get_command(cli_app)
        sections = _help_sections(root, [], self.state)[:1]
        for name, sub in root.commands.items():
            sections += _help_sections(sub, [name], self.state)
        return sections


def setup(app):
    app.connect("autodoc-process-docstring", escape_absolute_values, priority=100)
    app.connect("missing-reference", resolve_definition_paths)
    app.add_directive("railadhesion-cli", CliHelp)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
