"""Tests of the WILAC figures (railadhesion.plotting)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.figure import Figure

from railadhesion.models.wilac import WILAC_CONDITIONS, WilacCondition, WilacParameters
from railadhesion.plotting import (
    WILAC_GEOMETRIES,
    contact_semi_axes,
    plot_wilac_curves,
    plot_wilac_speeds,
    plot_wilac_water,
    plot_wilac_weights,
)


def _labelled(ax, *units):
    xl, yl = ax.get_xlabel(), ax.get_ylabel()
    assert xl and yl
    for unit in units:
        assert unit in xl + yl


@pytest.fixture(scope="module")
def constant_params():
    # A simple set (constant regressions; Polach 2005's dry and wet values as listed in the
    # project's MODELS.md §3) to check that a user-supplied set is honoured.
    dry = WilacCondition(k_A=1.0, k_S=0.4, mu0=0.55, A=0.4, B=0.6)
    wet = WilacCondition(k_A=0.3, k_S=0.1, mu0=0.3, A=0.4, B=0.2)
    return WilacParameters({"dry": dry, "damp2": wet, "damp1": wet, "wet": wet},
                           1e5, 40.0, (4e3, 1e5), (1.0, 40.0))


def test_geometries_quote_seed_000():
    # Seed 000 §4: tram wheel diameter 0.696 m, roller diameter 0.905 m, effective lateral
    # radius 0.660 m.
    tram = WILAC_GEOMETRIES["tram"]
    assert tram["wheel_radius"] == pytest.approx(0.696 / 2)
    assert tram["rail_radius"] == pytest.approx(0.905 / 2)
    assert tram["rail_lateral_radius"] == pytest.approx(0.660)
    assert math.isinf(tram["wheel_lateral_radius"])
    a, b = contact_semi_axes("tram", 4200.0)
    # Rolling-direction curvature (wheel + roller) exceeds the lateral one: a < b.
    assert 0 < a < b < 0.01


def test_contact_semi_axes_pass_through_and_errors():
    assert contact_semi_axes((0.004, 0.006), 1e4) == (0.004, 0.006)
    with pytest.raises(ValueError, match="geometry"):
        contact_semi_axes("bogus", 1e4)
    with pytest.raises(ValueError, match="normal_force"):
        contact_semi_axes("tram", -1.0)


def test_weights_figure():
    fig = plot_wilac_weights(n_points=101)
    assert isinstance(fig, Figure)
    ax_f, ax_e = fig.axes
    assert len(ax_f.lines) == len(WILAC_CONDITIONS) and len(ax_e.lines) == 3
    _labelled(ax_e, "µl/s")
    assert ax_f.get_ylabel()
    # The plotted weights sum to one at every water flow (seed 000 §5.3).
    total = sum(np.asarray(line.get_ydata()) for line in ax_f.lines)
    np.testing.assert_allclose(total, 1.0, atol=1e-12)


def test_curves_figure_default_set():
    fig = plot_wilac_curves(n_points=30)
    ax = fig.axes[0]
    assert len(ax.lines) == 5
    _labelled(ax, "%", "[-]")
    for line in ax.lines:
        x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
        # Traction at negative creep, adhesion positive (the paper's axes, Kalker's signs).
        assert np.all(x <= 0) and np.all(y >= 0) and y.max() > 0.05


def test_curves_figure_into_given_axes(constant_params):
    fig = Figure()
    ax = fig.add_subplot()
    out = plot_wilac_curves(water_flows=(0, 350), geometry=(0.004, 0.006), params=constant_params,
                            n_points=20, ax=ax)
    assert out is fig and len(ax.lines) == 2
    # Dry (mu0 0.55) above wet (mu0 0.3) in this set.
    assert np.max(ax.lines[0].get_ydata()) > np.max(ax.lines[1].get_ydata())


def test_water_figure():
    fig = plot_wilac_water(creeps=(0.03, 0.1, 0.3), marks=(25, 35, 60, 350), n_points=60)
    ax = fig.axes[0]
    # Three curves plus the marks inside the 0-100 µl/s axis (350 is outside).
    assert len(ax.lines) == 3 + 3
    _labelled(ax, "µl/s", "[-]")


def test_speeds_figure():
    fig = plot_wilac_speeds(n_points=30)
    ax = fig.axes[0]
    assert len(ax.lines) == 6
    _labelled(ax, "%", "[-]")
    fig = plot_wilac_speeds(speeds=(5, 10), compare_polach=False, n_points=30)
    assert len(fig.axes[0].lines) == 2


def test_bad_arguments():
    with pytest.raises(ValueError, match="creep_max"):
        plot_wilac_curves(creep_max=2.0)
    with pytest.raises(ValueError, match="water_flows"):
        plot_wilac_curves(water_flows=(-1,))
    with pytest.raises(ValueError, match="params"):
        plot_wilac_speeds(params="default")


# ---- issue 9, item 9: creep zoom, hidden curves said in the legend, labelled flow-rate marks


def test_creep_figures_have_a_zoom_panel_on_the_first_percent():
    fig = plot_wilac_curves(n_points=40)
    zoom, main = fig.axes
    assert zoom.get_xlim() == (-3.0, 0.0)
    assert main.get_xlim() == (-100.0, 0.0)
    # the zoom panel resolves the rise: many samples within 0-3 % creep
    x = np.asarray(zoom.lines[0].get_xdata())
    assert np.count_nonzero((x >= -3) & (x <= 0)) >= 100
    one = plot_wilac_speeds(n_points=30, zoom=None)
    assert len(one.axes) == 1


def test_hidden_curves_are_named_in_the_legend():
    fig = plot_wilac_curves(n_points=40)
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert "w = 350 µl/s (same as w = 60 µl/s)" in labels
    hidden = fig.axes[1].lines[-1]
    assert hidden.get_linestyle() != fig.axes[1].lines[-2].get_linestyle()
    fig = plot_wilac_speeds(n_points=40)
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert any("v = 10 m/s (same as WILAC, v = 10 m/s)" in lab for lab in labels)
    assert sum("same as" in lab for lab in labels) == 1  # only the truly coinciding curve


def test_flow_rate_marks_are_labelled():
    fig = plot_wilac_water(marks=(25, 35, 60), n_points=50)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "measured flow rates (25, 35, 60 µl/s)" in labels
    assert {t.get_text() for t in ax.texts} == {"25", "35", "60"}
