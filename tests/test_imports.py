"""Import paths and package structure (issue 9, item 7)."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import railadhesion

PACKAGE = Path(railadhesion.__file__).parent


def test_short_import_paths():
    from railadhesion.calibration import calibrate_wilac, fit_polach
    from railadhesion.io import load_parameter_file, read_creep_curve

    assert fit_polach.__module__ == "railadhesion.calibration.fitting"
    assert calibrate_wilac.__module__ == "railadhesion.calibration.pipeline"
    assert read_creep_curve.__module__ == "railadhesion.io.creepcurves"
    # the reader lives below the models (the WILAC model reads its default set with it);
    # railadhesion.io and railadhesion.io.paramfiles re-export it
    assert load_parameter_file.__module__ == "railadhesion.models.paramfiles"


def test_top_level_namespace_does_not_leak_helpers():
    import types

    public = {n for n in dir(railadhesion) if not n.startswith("_")}
    assert "np" not in public and "annotations" not in public
    # everything public is either exported or a submodule (loaded by some import)
    extra = {n for n in public - set(railadhesion.__all__)
             if not isinstance(getattr(railadhesion, n), types.ModuleType)}  # fmt: skip
    assert not extra, extra


def test_named_geometries_live_in_contact_with_a_plotting_alias():
    from railadhesion.contact import NAMED_GEOMETRIES, contact_semi_axes
    from railadhesion.plotting import WILAC_GEOMETRIES
    from railadhesion.plotting import contact_semi_axes as from_plotting

    assert from_plotting is contact_semi_axes is railadhesion.contact_semi_axes
    assert WILAC_GEOMETRIES is NAMED_GEOMETRIES
    assert contact_semi_axes.__module__ == "railadhesion.contact.geometry"


def _imports(module: str) -> set[str]:
    """Every railadhesion module ``module`` imports, at top level or inside functions."""
    path = PACKAGE.parent / (module.replace(".", "/") + ".py")
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
    return {m for m in found if m.startswith("railadhesion")}


def test_no_import_circle_between_parameter_files_and_the_wilac_model():
    assert "railadhesion.models.paramfiles" in _imports("railadhesion.models.wilac")
    assert "railadhesion.models.wilac" not in _imports("railadhesion.models.paramfiles")
    assert not any(m.startswith("railadhesion.io") for m in
                   _imports("railadhesion.models.wilac"))  # fmt: skip
    assert not any(m.startswith("railadhesion.io") for m in
                   _imports("railadhesion.models.wilac_parameters"))  # fmt: skip
    # the classes are the same objects from both modules
    wilac = importlib.import_module("railadhesion.models.wilac")
    base = importlib.import_module("railadhesion.models.wilac_parameters")
    assert wilac.WilacParameters is base.WilacParameters
    assert wilac.wilac_weights is base.wilac_weights


def test_moved_modules_keep_their_public_paths():
    # the parameter files moved to models/ and the adhesion-law file to braking/ (imports run
    # down the floors): the documented paths give the very same objects
    from railadhesion.braking import adhesion_law
    from railadhesion.identification import curves
    from railadhesion.io import paramfiles
    from railadhesion.models import paramfiles as low

    for name in paramfiles.__all__:
        assert getattr(paramfiles, name) is getattr(low, name), name
    for name in adhesion_law.__all__:
        assert getattr(curves, name) is getattr(adhesion_law, name), name
    import railadhesion.identification as ident

    for name in ("AdhesionLaw", "CurveFit", "falling_adhesion", "load_adhesion_law"):
        assert getattr(ident, name) is getattr(adhesion_law, name)
