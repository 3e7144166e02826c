"""Figures of the WILAC model (Trummer et al., seed 000, Figs. 5–9 and 11).

Every function returns a :class:`matplotlib.figure.Figure`. Figures are created with
:class:`matplotlib.figure.Figure` directly (no :mod:`matplotlib.pyplot` state, no display
needed; saving a PNG uses the Agg renderer), or drawn into an ``ax``/``fig`` you pass in.

Creep is plotted as the paper plots it: **traction at negative longitudinal creep**
``c_x = ξ < 0`` (Kalker's convention, ``docs/CONVENTIONS.md``), in per cent, and the adhesion
``T_x/Q`` (the force of the rail on the wheel, positive in traction) on the other axis.

Contact geometry is given by name (:data:`WILAC_GEOMETRIES`: ``"tram"``, the Pardubice tram
wheel rig of seed 000 §4, and ``"locomotive"``, the contact used for the locomotive-scale
checks of the default parameter set) or directly as the semi-axes ``(a, b)`` in metres.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from railadhesion._validate import (
    check_finite,
    check_nonnegative,
    check_positive,
    instance_or_default,
)

# The named contact geometries live in railadhesion.contact (re-exported here, where they
# were first defined, for compatibility).
from railadhesion.contact.geometry import WILAC_GEOMETRIES, contact_semi_axes

__all__ = [
    "WILAC_GEOMETRIES",
    "contact_semi_axes",
    "plot_wilac_weights",
    "plot_wilac_curves",
    "plot_wilac_water",
    "plot_wilac_speeds",
    "plot_fit",
]

_CREEP_LABEL = "longitudinal creep $c_x$ [%] (traction < 0)"
_ADHESION_LABEL = "adhesion $T_x/Q$ [-]"
_WATER_LABEL = "water flow rate $w$ [µl/s]"


def _params(params):
    from railadhesion.models.wilac import WilacParameters, default_wilac_parameters

    return instance_or_default(params, WilacParameters, "params", default_wilac_parameters,
                               expected="a WilacParameters or None")


def _axes(ax, figsize=(6.4, 4.4)):
    if ax is None:
        fig = Figure(figsize=figsize, layout="constrained")
        ax = fig.add_subplot()
    return ax.figure, ax


def _finish_adhesion_axes(ax, xlabel: str, title: str, xlim, **legend) -> None:
    """Labels, title, x range, adhesion axis from 0, grid and legend of the adhesion plots."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(_ADHESION_LABEL)
    ax.set_title(title)
    ax.set_xlim(*xlim)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(**legend)


def _creep_axes(ax, zoom):
    """(figure, main axes, zoom axes or None). A new figure gets two panels: the creep range
    0 to ``-zoom`` % on the left (where the curves rise and peak), the full range on the
    right, sharing the adhesion axis."""
    if ax is not None:
        return ax.figure, ax, None
    if zoom is None:
        fig, ax = _axes(None)
        return fig, ax, None
    zoom = float(check_positive(zoom, "zoom"))
    fig = Figure(figsize=(9.6, 4.6), layout="constrained")
    ax_zoom, ax_main = fig.subplots(1, 2, sharey=True, width_ratios=(1, 1.6))
    return fig, ax_main, ax_zoom


def _draw_distinguishable(axes, x, rows, labels, styles, tol=2e-3):
    """Plot ``rows`` on every axes of ``axes``; a row that lies within ``tol`` (adhesion) of an
    earlier one everywhere is drawn dotted with markers and its legend entry says which curve
    it hides under."""
    drawn = []
    for row, label, style in zip(rows, labels, styles, strict=True):
        style = dict(style)
        twin = next((lab for r, lab in drawn if np.nanmax(np.abs(row - r)) <= tol), None)
        if twin is not None:
            label = f"{label} (same as {twin})"
            style.update(ls=(0, (1, 2)), lw=2.2, marker="o", markevery=0.1, ms=4,
                         mfc="none")  # fmt: skip
        for i, ax in enumerate(axes):
            ax.plot(x, row, label=label if i == len(axes) - 1 else None, **style)
        drawn.append((row, label.split(" (same as")[0]))


def _finish_creep_panels(ax, ax_zoom, zoom, creep_max: float, title: str, **legend) -> None:
    """Finish the panels of :func:`_creep_panels`: the main axes (creep 0 to
    ``-100 creep_max`` %, :func:`_finish_adhesion_axes`) and the zoom panel, if any."""
    _finish_adhesion_axes(ax, _CREEP_LABEL, title, (-100 * float(creep_max), 0.0), **legend)
    if ax_zoom is None:
        return
    # the figure's title above both panels; the main panel: full range
    ax.figure.suptitle(ax.get_title())
    ax.set_title("full range")
    ax.set_ylabel("")
    ax_zoom.set_xlim(-float(zoom), 0.0)
    ax_zoom.set_ylim(bottom=0.0)
    ax_zoom.set_xlabel(f"creep $c_x$ [%], 0 to {-float(zoom):g} %")
    ax_zoom.set_ylabel(_ADHESION_LABEL)
    ax_zoom.set_title("rise and peak (zoom)")
    ax_zoom.grid(True, alpha=0.3)


def _creep_panels(geometry, q: float, ax, creep_max: float, n_points: int, zoom):
    """The contact semi-axes at the normal force ``q`` [N], the creepages of a traction
    creep-curve figure (negative, dense at low creep and in the zoomed range) and its panels:
    ``(a, b, creep, figure, main axes, zoom axes or None, the axes to draw on)``
    (:func:`_creep_axes`)."""
    a, b = contact_semi_axes(geometry, q)
    creep = -_traction_creep(creep_max, n_points)
    if zoom is not None:
        creep = np.unique(np.concatenate([creep, -np.linspace(0, float(zoom) / 100, 120)]))
    fig, ax, ax_zoom = _creep_axes(ax, zoom)
    return a, b, creep, fig, ax, ax_zoom, [x for x in (ax_zoom, ax) if x is not None]


def _traction_creep(creep_max: float, n_points: int) -> np.ndarray:
    """Magnitudes 0 … creep_max, dense at low creep (where the curves bend)."""
    creep_max = float(check_positive(creep_max, "creep_max"))
    if creep_max > 1:
        raise ValueError(f"creep_max must be in (0, 1], got {creep_max!r}")
    if int(n_points) < 10:
        raise ValueError(f"n_points must be in [10, inf), got {n_points!r}")
    return np.concatenate(([0.0], np.geomspace(1e-4 * creep_max, creep_max, int(n_points) - 1)))


def plot_wilac_weights(params=None, *, water_flow_max=100.0, n_points=401, fig=None):
    """Blending weights f_i(w) and transitions e_i(w) of WILAC (seed 000, Figs. 5 and 6).

    Parameters
    ----------
    params : WilacParameters, optional
        Parameter set whose ``transitions`` are drawn; ``None``: the default set.
    water_flow_max : float, optional
        Upper end of the water-flow axis [µl/s], > 0.
    n_points : int, optional
        Number of water-flow samples.
    fig : matplotlib.figure.Figure, optional
        Figure to draw into (two subplots are added); a new one by default.

    Returns
    -------
    matplotlib.figure.Figure
        Top panel: the four weights f_Dry, f_Damp2, f_Damp1, f_Wet; bottom: e_1, e_2, e_3.

    Notes
    -----
    Trummer et al. (seed 000), section 5.3, the equations for f_i and e_i, Table 1; computed
    with :func:`railadhesion.models.wilac.wilac_weights` and
    :func:`~railadhesion.models.wilac.wilac_transitions`.

    Examples
    --------
    >>> fig = plot_wilac_weights()
    >>> [len(ax.lines) for ax in fig.axes]
    [4, 3]
    """
    from railadhesion.models.wilac import WILAC_CONDITIONS, wilac_transitions, wilac_weights

    p = _params(params)
    wmax = float(check_positive(water_flow_max, "water_flow_max"))
    w = np.linspace(0.0, wmax, int(n_points))
    f = wilac_weights(w, p.transitions)
    e = wilac_transitions(w, p.transitions)
    if fig is None:
        fig = Figure(figsize=(6.4, 6.0), layout="constrained")
    ax_f, ax_e = fig.subplots(2, 1, sharex=True)
    names = {"dry": "Dry", "damp2": "Damp2", "damp1": "Damp1", "wet": "Wet"}
    for i, cond in enumerate(WILAC_CONDITIONS):
        ax_f.plot(w, f[i], label=f"$f_{{{names[cond]}}}$")
    ax_f.set_ylabel("weight $f_i$ [-]")
    ax_f.set_title("WILAC blending weights (Trummer et al., Fig. 5)")
    ax_f.legend(loc="center right")
    labels = ("Dry–Damp2", "Damp2–Damp1", "Damp1–Wet")
    for i in range(3):
        m, s = p.transitions[i]
        ax_e.plot(w, e[i], label=f"$e_{i + 1}$ ({labels[i]}; m = {m:g}, s = {s:g} µl/s)")
    ax_e.set_xlabel(_WATER_LABEL)
    ax_e.set_ylabel("transition $e_i$ [-]")
    ax_e.set_title("Transition functions (Fig. 6)")
    ax_e.legend(loc="lower right", fontsize="small")
    for ax in (ax_f, ax_e):
        ax.set_xlim(0.0, wmax)
        ax.set_ylim(-0.02, 1.02)
        ax.grid(True, alpha=0.3)
    return fig


def plot_wilac_curves(
    water_flows=(0, 25, 35, 60, 350),
    normal_force=4200.0,
    speed=5.0,
    geometry="tram",
    *,
    params=None,
    creep_max=1.0,
    n_points=200,
    zoom=3.0,
    ax=None,
):
    """Adhesion against longitudinal creep for several water flow rates (seed 000, Fig. 7).

    Parameters
    ----------
    water_flows : sequence of float, optional
        Water flow rates w [µl/s], one curve each.
    normal_force : float, optional
        Normal force Q [N]; default the tram rig's 4.2 kN.
    speed : float, optional
        Rolling speed v [m/s]; default the tram rig's 5 m/s.
    geometry : str or (float, float), optional
        Contact geometry: a key of :data:`WILAC_GEOMETRIES` or semi-axes ``(a, b)`` [m].
    params : WilacParameters, optional
        Parameter set; ``None``: the default set.
    creep_max : float, optional
        Largest creep magnitude [-], in (0, 1].
    n_points : int, optional
        Creep samples per curve.
    zoom : float or None, optional
        A new figure gets a left panel with the creep range 0 to ``-zoom`` % [%] (the rise
        and the peak, a few pixels wide on the full axis); ``None``: one panel.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into (one panel, no zoom); a new figure by default.

    Returns
    -------
    matplotlib.figure.Figure
        One line per water flow rate (per panel); x: creep c_x [%], traction negative as in
        the paper; y: T_x/Q [-]. A curve hidden under an earlier one (e.g. 60 and 350 µl/s,
        both "wet") is dotted with markers and its legend entry says so.

    Notes
    -----
    Forces from :func:`railadhesion.models.wilac.wilac_forces` (seed 000, section 5), pure
    longitudinal creep, no spin.

    Examples
    --------
    >>> fig = plot_wilac_curves(water_flows=(0, 350), n_points=20)
    >>> [len(ax.lines) for ax in fig.axes]     # zoom panel, full range
    [2, 2]
    """
    from railadhesion.models.wilac import wilac_forces

    p = _params(params)
    q = float(check_positive(normal_force, "normal_force"))
    v = float(check_nonnegative(speed, "speed"))
    flows = check_nonnegative(np.atleast_1d(np.asarray(water_flows, dtype=float)), "water_flows")
    a, b, creep, fig, ax, ax_zoom, axes = _creep_panels(geometry, q, ax, creep_max, n_points, zoom)
    fx, _ = wilac_forces(creep[None, :], 0.0, 0.0, q, v, a, b, flows[:, None], p)
    _draw_distinguishable(
        axes, 100 * creep, list(np.asarray(fx) / q), [f"w = {w:g} µl/s" for w in flows],
        [{"color": f"C{i}"} for i in range(flows.size)],
    )  # fmt: skip
    _finish_creep_panels(
        ax, ax_zoom, zoom, creep_max,
        f"WILAC, Q = {q / 1e3:g} kN, v = {v:g} m/s (cf. Trummer et al., Fig. 7)",
    )  # fmt: skip
    return fig


def plot_wilac_water(
    creeps=(0.03, 0.1, 0.3, 0.6),
    normal_force=4200.0,
    speed=5.0,
    geometry="tram",
    *,
    params=None,
    water_flow_max=100.0,
    marks=(25, 35, 60),
    n_points=301,
    ax=None,
):
    """Adhesion against water flow rate at fixed traction creeps (seed 000, Fig. 8).

    Parameters
    ----------
    creeps : sequence of float, optional
        Creep magnitudes |c_x| [-]; each is applied as traction, c_x = −|c_x|.
    normal_force : float, optional
        Normal force Q [N].
    speed : float, optional
        Rolling speed v [m/s].
    geometry : str or (float, float), optional
        A key of :data:`WILAC_GEOMETRIES` or semi-axes ``(a, b)`` [m].
    params : WilacParameters, optional
        Parameter set; ``None``: the default set.
    water_flow_max : float, optional
        Upper end of the water-flow axis [µl/s].
    marks : sequence of float, optional
        Water flow rates marked by labelled grey dotted vertical lines, one legend entry for
        all (the paper marks the rates where it measured; those above ``water_flow_max`` are
        skipped).
    n_points : int, optional
        Water-flow samples.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.figure.Figure
        One line per creep, plus one vertical line per mark within the axis.

    Examples
    --------
    >>> fig = plot_wilac_water(creeps=(0.03, 0.6), marks=(25,), n_points=50)
    >>> len(fig.axes[0].lines)
    3
    """
    from railadhesion.models.wilac import wilac_forces

    p = _params(params)
    q = float(check_positive(normal_force, "normal_force"))
    v = float(check_nonnegative(speed, "speed"))
    wmax = float(check_positive(water_flow_max, "water_flow_max"))
    mags = np.abs(check_finite(np.atleast_1d(np.asarray(creeps, dtype=float)), "creeps"))
    a, b = contact_semi_axes(geometry, q)
    w = np.linspace(0.0, wmax, int(n_points))
    fig, ax = _axes(ax)
    fx, _ = wilac_forces(-mags[:, None], 0.0, 0.0, q, v, a, b, w[None, :], p)
    for c, row in zip(mags, np.asarray(fx) / q, strict=True):
        ax.plot(w, row, label=f"$c_x$ = {-100 * c:g} %")
    shown = [float(m) for m in marks if 0 <= m <= wmax]
    for i, m in enumerate(shown):
        label = (
            f"measured flow rates ({', '.join(f'{x:g}' for x in shown)} µl/s)"
            if i == 0
            else None
        )
        ax.axvline(m, color="0.5", lw=0.9, ls=":", zorder=0, label=label)
        ax.annotate(f"{m:g}", (m, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -10),
                    textcoords="offset points", color="0.4", fontsize="small")  # fmt: skip
    _finish_adhesion_axes(
        ax,
        _WATER_LABEL,
        f"WILAC, Q = {q / 1e3:g} kN, v = {v:g} m/s (cf. Trummer et al., Fig. 8)",
        (0.0, wmax),
    )
    return fig


def plot_wilac_speeds(
    speeds=(5, 10, 20),
    water_flow=0.0,
    normal_force=110e3,
    geometry="locomotive",
    *,
    params=None,
    compare_polach=True,
    polach_speed=10.0,
    creep_max=0.6,
    n_points=200,
    zoom=3.0,
    ax=None,
):
    """Adhesion against creep at several speeds (seed 000, Fig. 9; with Fig. 11's comparison).

    Parameters
    ----------
    speeds : sequence of float, optional
        Rolling speeds v [m/s], one WILAC curve each (solid).
    water_flow : float, optional
        Water flow rate w [µl/s]; 0 is the dry condition.
    normal_force : float, optional
        Normal force Q [N]; default 110 kN, the locomotive tests of the paper.
    geometry : str or (float, float), optional
        A key of :data:`WILAC_GEOMETRIES` or semi-axes ``(a, b)`` [m].
    params : WilacParameters, optional
        Parameter set; ``None``: the default set.
    compare_polach : bool, optional
        Also draw (dashed) the plain Polach model with parameters fixed at their WILAC values
        for ``polach_speed``, as the paper's Fig. 11 does.
    polach_speed : float, optional
        Speed [m/s] whose WILAC Polach parameters are frozen for the comparison.
    creep_max : float, optional
        Largest creep magnitude [-], in (0, 1].
    n_points : int, optional
        Creep samples per curve.
    zoom : float or None, optional
        A new figure gets a left panel with the creep range 0 to ``-zoom`` % [%];
        ``None``: one panel.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into (one panel, no zoom).

    Returns
    -------
    matplotlib.figure.Figure
        ``len(speeds)`` solid lines, and as many dashed ones if ``compare_polach`` (per
        panel). The fixed-parameter curve at ``polach_speed`` coincides with WILAC's there:
        it is dotted with markers and its legend entry says so.

    Notes
    -----
    The frozen-parameter curves use each condition's Polach parameters at
    ``(normal_force, polach_speed)`` (:meth:`~railadhesion.models.wilac.WilacParameters.
    polach_parameters`), evaluated with :func:`railadhesion.models.polach.polach_forces` at each
    speed and blended with the same water-flow weights (seed 000, section 5.4, Fig. 11).

    Examples
    --------
    >>> fig = plot_wilac_speeds(speeds=(5, 20), n_points=20)
    >>> [len(ax.lines) for ax in fig.axes]     # zoom panel, full range
    [4, 4]
    """
    from railadhesion.models.polach import polach_forces
    from railadhesion.models.wilac import WILAC_CONDITIONS, wilac_forces, wilac_weights

    p = _params(params)
    q = float(check_positive(normal_force, "normal_force"))
    w = float(check_nonnegative(water_flow, "water_flow"))
    vs = check_nonnegative(np.atleast_1d(np.asarray(speeds, dtype=float)), "speeds")
    a, b, creep, fig, ax, ax_zoom, axes = _creep_panels(geometry, q, ax, creep_max, n_points, zoom)
    fx, _ = wilac_forces(creep[None, :], 0.0, 0.0, q, vs[:, None], a, b, w, p)
    colors = [f"C{i}" for i in range(len(vs))]
    rows = list(np.asarray(fx) / q)
    labels = [f"WILAC, v = {v:g} m/s" for v in vs]
    styles = [{"color": col} for col in colors]
    if compare_polach:
        vp = float(check_nonnegative(polach_speed, "polach_speed"))
        weights = wilac_weights(w, p.transitions)
        total = np.zeros((vs.size, creep.size))
        for i, cond in enumerate(WILAC_CONDITIONS):
            if weights[i] == 0:
                continue
            pp = p.polach_parameters(cond, q, vp)
            fxi, _ = polach_forces(
                creep[None, :], 0.0, 0.0, q, vs[:, None], a, b,
                mu0=pp["mu0"], k_A=pp["k_A"], k_S=pp["k_S"], A=pp["A"], B=pp["B"],
            )
            total = total + weights[i] * np.asarray(fxi)
        for v, row, col in zip(vs, total / q, colors, strict=True):
            rows.append(row)
            labels.append(f"Polach, fixed parameters of {vp:g} m/s, v = {v:g} m/s")
            styles.append({"color": col, "ls": "--"})
    _draw_distinguishable(axes, 100 * creep, rows, labels, styles)
    _finish_creep_panels(
        ax, ax_zoom, zoom, creep_max,
        f"WILAC, Q = {q / 1e3:g} kN, w = {w:g} µl/s (cf. Trummer et al., Figs. 9 and 11)",
        fontsize="small",
    )  # fmt: skip
    return fig


def plot_fit(result, *, title: str = "", n_points: int = 200, ax=None):
    """Fitted model against the measured creep curve (a fit result of Polach or Fletcher).

    ``result`` comes from :func:`~railadhesion.calibration.fitting.fit_polach` or
    :func:`~railadhesion.calibration.fitting.fit_fletcher`.

    Parameters
    ----------
    result : FitResult
        The fit; its data (``creep``, ``adhesion``) and model (``predict``) are drawn.
    title : str, optional
        Axes title; default names the model, R² and RMSE.
    n_points : int, optional
        Samples of the model curve.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.figure.Figure
        Markers: measured adhesion; line: the fitted model over the measured creep range
        (at the data points only when the fit had per-point conditions); x: |creep| [%].

    Examples
    --------
    >>> import numpy as np
    >>> from railadhesion.calibration import fit_polach
    >>> creep = -np.geomspace(1e-5, 0.3, 12)
    >>> from railadhesion.models.polach import polach_forces
    >>> fx, _ = polach_forces(creep, 0, 0, 4200.0, 5.0, 4e-3, 3e-3, mu0=0.3, k_A=0.5)
    >>> res = fit_polach(creep, np.abs(fx) / 4200, normal_force=4200.0, speed=5.0, a=4e-3,
    ...                  b=3e-3, fit=("mu0", "k_A"))
    >>> len(plot_fit(res).axes[0].lines)
    2
    """
    creep = np.asarray(result.creep, dtype=float)
    fig, ax = _axes(ax)
    order = np.argsort(np.abs(creep))
    ax.plot(100 * np.abs(creep[order]), np.asarray(result.adhesion)[order], "o", ms=4,
            color="0.2", label=f"measured ({result.n_points} points)")  # fmt: skip
    per_point = any(np.ndim(v) > 0 for v in result.conditions.values())
    if per_point:
        c = creep[order]
        model = np.asarray(result.predict())[order]
    else:
        sign = -1.0 if np.mean(creep) < 0 else 1.0
        mags = np.abs(creep)
        top = float(mags.max())
        c = sign * np.unique(np.concatenate(
            [np.linspace(0.0, top, int(n_points)), np.geomspace(top * 1e-4, top, int(n_points))]
        ))  # fmt: skip
        model = np.asarray(result.predict(c))
    fitted = ", ".join(result.fitted)
    ax.plot(100 * np.abs(c), model, color="C0",
            label=f"{result.model.capitalize()} fit ({fitted})")  # fmt: skip
    ax.set_xlabel("|creep| [%]")
    ax.set_ylabel("adhesion |T|/Q [-]")
    ax.set_title(
        title or f"{result.model.capitalize()} fit: R² = {result.r_squared:.4f}, "
        f"RMSE = {result.rmse:.3g}"
    )
    ax.set_xlim(left=0.0)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return fig
