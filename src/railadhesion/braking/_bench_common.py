"""What the WSP bench (:mod:`railadhesion.braking.bench`) and the odometry bench
(:mod:`railadhesion.braking.odometry_bench`) share, private to the braking package: reading a
programme file and picking its cases, loading a user's component or an FMU, the loop over
the cases with its result base, and the output files.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import math
import os
import time as _time
from dataclasses import dataclass, replace
from pathlib import Path

from railadhesion.braking._fields import read_document

_DATA = Path(__file__).resolve().parent.parent / "data"


# -- programme files and cases ---------------------------------------------------------------
def select_cases(programme, names):
    """A copy of ``programme`` (a dataclass with a list ``cases`` of named cases) with the
    cases named in ``names`` only, in the programme's order; ``ValueError`` for an unknown
    name."""
    wanted = list(names)
    known = {c.name for c in programme.cases}
    missing = [n for n in wanted if n not in known]
    if missing:
        raise ValueError(f"unknown case(s) {missing}; the programme has "
                         f"{', '.join(c.name for c in programme.cases)}")
    return replace(programme, cases=[c for c in programme.cases if c.name in wanted])


def case_field(key, tab, defaults, fallback, where):
    """A field of a programme's case: ``(value, where it is given)`` from the case's table
    ``tab`` (at ``where``), else from the programme's ``[defaults]``, else ``fallback[key]``
    (the default value, reported at ``where``)."""
    if key in tab:
        return tab[key], f"{where}.{key}"
    if key in defaults:
        return defaults[key], f"defaults.{key}"
    return fallback[key], f"{where}.{key}"


def read_programme_file(path, default: str, build):
    """Read a programme file: ``path``, or the package's data file ``default`` for
    ``"default"``; ``build(document, folder of the file)`` makes the programme, whose
    ``source`` is set to the file's label. Its errors (a field's, or ``ValueError``) become a
    :class:`~railadhesion.braking.BrakingFileError` naming the file."""
    if os.fspath(path) == "default":
        path = _DATA / default

    def labelled_programme(doc, label):
        prog = build(doc, Path(os.fspath(path)).resolve().parent)
        prog.source = label
        return prog

    return read_document(path, labelled_programme)


# -- a user's component, an FMU --------------------------------------------------------------
def load_attribute(text: str, what: str, prefix: str):
    """The object ``"module:name"`` or ``"file.py:name"`` names (a file is imported as module
    ``prefix + its stem``); errors name ``what`` and the specification."""
    where, name = text.rsplit(":", 1)
    if where.endswith(".py"):
        path = Path(where)
        if not path.is_file():
            raise ValueError(f"{what} file not found: {path}")
        mspec = importlib.util.spec_from_file_location(f"{prefix}{path.stem}", path)
        module = importlib.util.module_from_spec(mspec)
        mspec.loader.exec_module(module)
    else:
        module = importlib.import_module(where)
    if not hasattr(module, name):
        raise ValueError(f"{what} {text!r}: {where} has no attribute {name!r}")
    return getattr(module, name)


def load_component(text: str, what: str, default: str, prefix: str):
    """A bench's controller or odometry (``what``) given as a string that is not a ``.fmu``
    path: the object ``"module:name"`` or ``"file.py:name"`` names (:func:`load_attribute`);
    ``ValueError`` listing the forms (``default``, a .fmu file, those two) otherwise."""
    if ":" not in text:
        raise ValueError(f"{what} {text!r}: give {default!r}, a .fmu file, or "
                         "'module:name' / 'file.py:name'")
    return load_attribute(text, what, prefix)


def read_cosim_fmu(path, period: float | None = None, what: str = "FMU"):
    """Open an FMI 2.0 co-simulation FMU with FMPy: ``(path, model description, variables by
    name, period)``; the period is ``period``, else the FMU's DefaultExperiment step size, else
    5 ms. ``what`` names the FMU in the ImportError without FMPy."""
    try:
        from fmpy import read_model_description
    except ImportError as exc:  # pragma: no cover - fmpy is in the fmu extra
        raise ImportError(f"{what} needs FMPy: pip install 'railadhesion[fmu]'") from exc
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"FMU file not found: {path}")
    try:
        md = read_model_description(str(path))
    except Exception as exc:  # FMPy raises several kinds for a broken archive
        raise ValueError(f"{path}: not a readable FMU: {exc}") from None
    if md.coSimulation is None:
        raise ValueError(f"{path}: not a co-simulation FMU (FMI 2.0 CS needed)")
    variables = {v.name: v for v in md.modelVariables}
    step = getattr(md.defaultExperiment, "stepSize", None) if (
        md.defaultExperiment is not None) else None
    if period is None:
        period = float(step) if step else 5e-3
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"period must be in (0, inf) s, got {period!r}")
    return path, md, variables, float(period)


def fmu_variable_problems(variables, missing, want) -> str:
    """What is wrong with the ``variables`` of an FMU (FMPy's, by name) for a bench: it lacks
    the ``missing`` ones, or has one of ``want`` = [(name, causality)] with another causality;
    ``""`` if nothing."""
    wrong = [f"{name} (is {variables[name].causality}, must be {c})" for name, c in want
             if name in variables and variables[name].causality != c]
    parts = []
    if missing:
        parts.append("lacks the variables " + ", ".join(missing))
    if wrong:
        parts.append("has " + ", ".join(wrong))
    return " and ".join(parts)


def release_fmu(fmu) -> None:
    """Terminate and free an FMPy FMU instance; an FMU already broken is let go silently."""
    try:
        fmu.terminate()
        fmu.freeInstance()
    except Exception:  # pragma: no cover - the FMU is already broken
        pass


def whole_multiple(period: float, step: float, what: str, of: str) -> int:
    """``period / step``, a whole number >= 1 (to 1e-9 of ``period``), else ``ValueError``:
    "``what`` (``period`` s) must be a whole multiple of ``of`` (``step`` s)"."""
    ratio = int(round(period / step))
    if ratio < 1 or abs(ratio * step - period) > 1e-9 * period:
        raise ValueError(f"{what} ({period} s) must be a whole multiple of {of} ({step} s)")
    return ratio


# -- the loop over the cases, the result -----------------------------------------------------
@dataclass
class ProgrammeResult:
    """What the results of the WSP and the odometry bench share: the programme's name and (a
    field of each subclass) ``cases``, the summary dict of every case."""

    programme: str

    @property
    def failed(self) -> list:
        """Names of the cases that did not run to the end or failed a check."""
        return [c["name"] for c in self.cases if not c.get("passed", False)]

    @staticmethod
    def table_row(summary: dict) -> dict:
        """The scalar figures of a case's (or a fit's) ``summary``, a row of the tables."""
        return {k: v for k, v in summary.items() if not isinstance(v, dict | list)}

    @staticmethod
    def add_checks(row: dict, summary: dict) -> dict:
        """``row`` with a column ``check_<name>`` (passed or not) per check of ``summary``."""
        for name, check in summary.get("checks", {}).items():
            row[f"check_{name}"] = check["passed"]
        return row


class ProgrammeRun:
    """The loop of a bench over the cases of a programme (the WSP and the odometry bench).

    :meth:`run` runs the cases in turn. A bench subclasses it with what differs: how a case
    runs (:meth:`run_case`), what a case that raised records (:meth:`error_summary`), the
    bench's result (:meth:`result`) and its output writer (:meth:`write_outputs`); and, as
    data, the exceptions that fail a case but let the others run (:attr:`case_errors`) and
    what such a case leaves to write beside its summary (:attr:`no_record`).
    """

    #: Exceptions of a case that record it as failed; the next case still runs.
    case_errors: tuple[type[Exception], ...] = ()
    #: What a failed case gives the writer in place of its records (histories, traces).
    no_record: tuple = ()

    def __init__(self, programme: str, unit):
        self.programme = programme  # the programme's name
        self.unit = unit  # the controller or odometry under test
        self.label = getattr(unit, "label", "?")

    def run_case(self, case) -> tuple:
        """``(summary, *records)`` of one case; the records are handed to the writer."""
        raise NotImplementedError

    def error_summary(self, case, message: str, seconds: float) -> dict:
        """The summary of a case that raised one of :attr:`case_errors`: ``message`` is
        ``"Type: text"``, ``seconds`` the wall time until then."""
        raise NotImplementedError

    def result(self, summaries: list):
        """The bench's result for the case summaries so far."""
        raise NotImplementedError

    def write_outputs(self, result, out, *, case=None, figures: bool = True,
                      histories: bool = False, summary_figure: bool = False) -> list:
        """Write the outputs of ``result`` (and of ``case = (case, summary, *records)``)."""
        raise NotImplementedError

    def run(self, cases, *, out=None, figures: bool = True, histories: bool = False,
            progress=None):
        """Run ``cases`` and return the result. ``progress(index, number of cases, case
        name)`` is called before each case. With ``out`` the outputs are rewritten after
        every case, and at the end (``figures``) with the figure across cases. The unit under
        test is closed (its ``close()``, if it has one) after the last case, also on an
        error."""
        summaries = []
        out = Path(out) if out is not None else None
        try:
            for k, case in enumerate(cases):
                if progress is not None:
                    progress(k, len(cases), case.name)
                started = _time.perf_counter()
                try:
                    summary, *records = self.run_case(case)
                except self.case_errors as exc:
                    summary = self.error_summary(case, f"{type(exc).__name__}: {exc}",
                                                 _time.perf_counter() - started)
                    records = self.no_record
                summaries.append(summary)
                if out is not None:
                    self.write_outputs(self.result(summaries), out,
                                       case=(case, summary, *records), figures=figures,
                                       histories=histories)
        finally:
            close = getattr(self.unit, "close", None)
            if close is not None:
                close()
        result = self.result(summaries)
        if out is not None and figures and summaries:
            self.write_outputs(result, out, summary_figure=True)
        return result


# -- output files ----------------------------------------------------------------------------
def json_safe(obj):
    """A JSON-safe copy of nested dicts and lists: NaN and inf become null, NumPy scalars
    Python numbers."""
    if isinstance(obj, dict):
        return {str(k): json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_safe(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if hasattr(obj, "item") and not isinstance(obj, str | bytes):
        return json_safe(obj.item())
    return obj


def write_json(path: Path, doc) -> Path:
    """Write ``doc`` (made :func:`json_safe`) as indented UTF-8 JSON, through a temporary file
    so that a reader never sees half a file (the benches rewrite their summary after every
    case). Returns ``path``."""
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(json_safe(doc), indent=2, ensure_ascii=False) + "\n",
                   encoding="utf-8")
    tmp.replace(path)
    return path


def save_figure(fig, out: Path, name: str, dpi: int) -> Path:
    """Save a bench figure as ``out/figures/<name>.png`` and return its path."""
    (out / "figures").mkdir(exist_ok=True)
    path = out / "figures" / f"{name}.png"
    fig.savefig(path, dpi=dpi)
    return path


def write_summary(out: Path, doc: dict, tables: dict) -> list:
    """A bench's files across its cases, in the folder ``out`` (made if needed):
    ``summary.json`` (``doc``), then every table of ``tables`` (file name: DataFrame) as CSV.
    Returns the paths."""
    out.mkdir(parents=True, exist_ok=True)
    written = [write_json(out / "summary.json", doc)]
    for name, frame in tables.items():
        frame.to_csv(out / name, index=False, float_format="%.6g")
        written.append(out / name)
    return written


def write_case(out: Path, name: str, summary: dict, figure=None, history=None, *,
               dpi: int) -> list:
    """One case's files in the folder ``out``: ``cases/<name>.json`` (``summary``), then, if
    given, the matplotlib ``figure`` as ``figures/<name>.png`` (at ``dpi``) and the DataFrame
    ``history`` as ``histories/<name>.parquet``. Returns the paths."""
    (out / "cases").mkdir(exist_ok=True)
    written = [write_json(out / "cases" / f"{name}.json", summary)]
    if figure is not None:
        written.append(save_figure(figure, out, name, dpi))
    if history is not None:
        (out / "histories").mkdir(exist_ok=True)
        path = out / "histories" / f"{name}.parquet"
        history.to_parquet(path, index=False)
        written.append(path)
    return written
