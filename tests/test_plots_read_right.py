"""The run's PNG plots tell the truth on spur, helical and misaligned helical runs (issue 46): the
decisions behind them, not their pixels.

- ``bearing_pattern.png``: the colour scale ends at the largest pressure away from the flank
  edges, never at an edge value; an ellipse the flank cannot hold is a line contact, drawn as
  its contact line clipped to the flank.
- ``load_share.png``: a pair is drawn only where it carries load (NaN elsewhere).
- ``te.png``: the positions left out of the loaded TE are marked, one marker each.
- ``p_max.png``: the edge values written above the range do not overprint each other.
- ``line_load.png``: the legends lie outside the axes; the stiffness axis starts at zero.
"""

from __future__ import annotations

from types import SimpleNamespace as NS

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from fegear.output import cylindrical_output, gear_plots  # noqa: E402
from fegear.output.p_max_plot import label_picks, p_max_series, plot_p_max  # noqa: E402
from fegear.output.pattern_plot import colour_scale  # noqa: E402
from fegear.tca.plots import clip_to_box, contact_kind, contact_line, draw_ellipses  # noqa: E402


def _pair(k: int, force: float, share: float = 0.5, p_int=None, p_edge=None):
    return NS(k=k, j=-k, force_N=force, load_share=share, p_interior_MPa=p_int,
              p_edge_MPa=p_edge, in_contact=force > 0)  # fmt: skip


def _cells(pressure, boundary):
    return NS(boundary=np.asarray(boundary, dtype=bool)), np.asarray(pressure, dtype=float)


def _position(pairs, cells=(), status="ok", unloaded_contact=True):
    return NS(pairs=tuple(pairs), cells=tuple(c for c, _ in cells),
              pressure=tuple(p for _, p in cells), status=status,
              unloaded_contact=unloaded_contact)  # fmt: skip


# ---- bearing_pattern.png: the colour scale -------------------------------------------------


def test_colour_scale_ends_at_the_interior_maximum_not_the_edge_one():
    """ISO/TR 6336-30 ex. 1: edge cells at 7-12.6 GPa, the interior at about 1 GPa: the scale
    ends at the interior maximum, the edge maximum is reported apart."""
    a = _cells([900.0, 1000.0, 12600.0], [False, False, True])
    b = _cells([950.0, 7000.0], [False, True])
    pos = [
        _position([_pair(0, 1.0, p_int=1000.0, p_edge=12600.0)], [a]),
        _position([_pair(1, 1.0, p_int=950.0, p_edge=7000.0)], [b]),
    ]
    s = colour_scale(pos)
    assert s.vmax == 1000.0 and s.edge_max == 12600.0 and s.cell_max == 12600.0


def test_colour_scale_without_pair_values_uses_the_cells_off_the_boundary():
    """No pair has an interior value (all None): the largest loaded cell off a flank boundary
    sets the scale, still not the edge cell."""
    pos = [_position([_pair(0, 1.0, p_edge=8000.0)], [_cells([700.0, 8000.0], [False, True])])]
    assert colour_scale(pos).vmax == 700.0


def test_colour_scale_reads_the_usable_positions_first():
    """A degenerate position's interior value (an unresolved patch) does not set the scale when
    usable positions exist."""
    c = _cells([1.0], [False])
    pos = [_position([_pair(0, 1.0, p_int=1100.0)], [c]),
           _position([_pair(0, 1.0, p_int=5000.0)], [c], status="degenerate")]  # fmt: skip
    assert colour_scale(pos).vmax == 1100.0


# ---- bearing_pattern.png: ellipses or contact lines ----------------------------------------

_BOUNDS = NS(u_fillet=4.0, u_tip=18.0, v_start=-50.0, v_end=50.0)


def _ellipse(a_mm: float, b_mm: float, line_contact: bool = False, uv=(10.0, 0.0)):
    """An ellipse at ``uv`` on a flank whose coordinates are the tangent plane's (u along x,
    v along y), its major axis along the face (v), tilted by 5° toward the tip."""
    t = np.radians(5.0)
    major = np.array([np.sin(t), np.cos(t), 0.0])
    minor = np.array([np.cos(t), -np.sin(t), 0.0])
    T = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    c = NS(pinion_tangents=T, gear_tangents=T, major_axis=major, minor_axis=minor)
    hz = None if line_contact else NS(a_mm=a_mm, b_mm=b_mm)
    return NS(curvature=c, pinion_uv=np.array(uv), gear_uv=np.array(uv), hertz=hz,
              line_contact=line_contact, paint_a_mm=None, paint_b_mm=b_mm,
              pinion_torque_Nm=100.0)  # fmt: skip


def test_an_ellipse_longer_than_the_flank_is_a_line_contact():
    """ISO/TR 6336-30 ex. 1: a Hertz semi-axis of 441 mm on a 100 mm face is a line contact; a
    5 × 1 mm ellipse on the same flank is a point contact."""
    assert contact_kind(_ellipse(441.0, 0.2), "pinion", "hertz", _BOUNDS) == "line"
    assert contact_kind(_ellipse(5.0, 1.0), "pinion", "hertz", _BOUNDS) == "point"
    assert contact_kind(_ellipse(0.0, 0.2, line_contact=True), "pinion", "hertz") == "line"
    # no Hertz ellipse (no load) and not a line contact: nothing to draw
    e = _ellipse(5.0, 1.0)
    e.hertz = None
    assert contact_kind(e, "pinion", "hertz", _BOUNDS) == "none"


def test_an_ellipse_taller_than_the_flank_is_a_line_contact():
    """The flank's profile extent (14 mm) holds less than its face: an ellipse 40 mm long
    across the profile does not fit, though it would along the face."""
    e = _ellipse(20.0, 1.0)
    e.curvature.major_axis, e.curvature.minor_axis = (np.array([1.0, 0, 0]),
                                                      np.array([0, -1.0, 0]))  # fmt: skip
    assert contact_kind(e, "pinion", "hertz", _BOUNDS) == "line"


def test_the_contact_line_is_clipped_to_the_flank():
    """The contact line of a line contact runs along the major axis through the contact point
    and ends on the flank's boundary (to round-off: 1e-9 mm)."""
    seg = contact_line(_ellipse(441.0, 0.2), "pinion", _BOUNDS)
    assert seg is not None and seg.shape == (2, 2)
    u, v = seg[:, 0], seg[:, 1]
    assert np.all(u >= 4.0 - 1e-9) and np.all(u <= 18.0 + 1e-9)
    assert np.all(v >= -50.0 - 1e-9) and np.all(v <= 50.0 + 1e-9)
    assert sorted(v) == pytest.approx([-50.0, 50.0], abs=1e-9)  # 5° tilt: the face ends
    d = np.diff(seg, axis=0)[0]
    assert d[0] / d[1] == pytest.approx(np.tan(np.radians(5.0)), rel=1e-12)  # along the axis
    assert clip_to_box(np.array([30.0, 0.0]), np.array([0.0, 1.0]),
                       np.array([4.0, -50.0]), np.array([18.0, 50.0])) is None  # fmt: skip


def test_draw_ellipses_draws_lines_for_line_contacts_and_ellipses_for_points():
    """A helical pair's 25 positions: 25 contact lines and no ellipse; a localised contact's
    positions: ellipses and no line (the point-contact families keep their ellipses)."""
    fig, ax = plt.subplots()
    d = draw_ellipses(ax, [_ellipse(441.0, 0.2)] * 25 + [None], "pinion", ("hertz",),
                      bounds=_BOUNDS)  # fmt: skip
    assert (d.ellipses, d.lines) == (0, 25)
    d = draw_ellipses(ax, [_ellipse(5.0, 1.0)] * 3, "pinion", ("hertz",), bounds=_BOUNDS)
    assert (d.ellipses, d.lines) == (3, 0)
    d = draw_ellipses(ax, [_ellipse(441.0, 0.2)], "pinion", ("hertz",), bounds=_BOUNDS,
                      lines=False)  # fmt: skip
    assert not d
    plt.close(fig)


# ---- load_share.png -----------------------------------------------------------------------


def test_load_share_is_nan_where_the_pair_is_out_of_contact():
    """A pair's curve starts and ends where its contact does: NaN (a gap), never 0, where it
    carries no load or is not modelled."""
    cycle = NS(positions=(
        _position([_pair(0, 10.0, 0.7), _pair(1, 5.0, 0.3)]),
        _position([_pair(0, 10.0, 1.0), _pair(1, 0.0, 0.0)]),
        _position([_pair(-1, 2.0, 0.2), _pair(0, 8.0, 0.8)]),
        _position([]),  # lost
    ))  # fmt: skip
    s = gear_plots.per_pair(cycle, "load_share")
    assert sorted(s) == [-1, 0, 1]
    np.testing.assert_array_equal(s[1], [0.3, np.nan, np.nan, np.nan])
    np.testing.assert_array_equal(s[-1], [np.nan, np.nan, 0.2, np.nan])
    np.testing.assert_array_equal(s[0], [0.7, 1.0, 0.8, np.nan])


# ---- te.png -------------------------------------------------------------------------------


def _te_cycle():
    status = ["ok", "degenerate", "ok", "lost", "degenerate", "ok"]
    return NS(
        phi1=np.radians(np.arange(6.0)),
        te_loaded_arcsec=np.array([-11.0, -30.0, -11.2, 0.0, -25.0, -11.1]),
        te_unloaded_arcsec=np.zeros(6),
        positions=tuple(_position([], status=s, unloaded_contact=s != "lost") for s in status),
    )


def test_te_series_leaves_the_excluded_positions_out_of_the_loaded_line():
    s = gear_plots.te_series(_te_cycle())
    assert {k: v.tolist() for k, v in s.left_out.items()} == {"degenerate": [1, 4], "lost": [3]}
    assert np.isnan(s.loaded[[1, 3, 4]]).all() and np.isfinite(s.loaded[[0, 2, 5]]).all()
    assert np.isnan(s.unloaded[3]) and np.isfinite(s.unloaded[[0, 1, 2, 4, 5]]).all()


def test_te_plot_marks_each_excluded_position_once(tmp_path, monkeypatch):
    """The open markers "left out: …" number the excluded positions (2 degenerate, 1 lost)."""
    figs = []
    monkeypatch.setattr(gear_plots, "_save", lambda fig, path: figs.append(fig) or path)
    run = NS(cycle=_te_cycle(),
             case=NS(name="t", torque2_Nm=1.0, fidelity="hybrid", level=0))  # fmt: skip
    head = NS(te_pp_unloaded_arcsec=0.0, te_pp_loaded_arcsec=0.2,
              te_pp_loaded_positions_used=3, n_positions=6)  # fmt: skip
    gear_plots._plot_te(tmp_path, run, NS(cycle=head))
    ax = figs[0].axes[0]
    marks = [ln for ln in ax.lines if ln.get_label().startswith("left out")]
    assert sum(len(ln.get_xdata()) for ln in marks) == 3
    assert {ln.get_label() for ln in marks} == {"left out: degenerate (2)", "left out: lost (1)"}
    plt.close(figs[0])


# ---- p_max.png ----------------------------------------------------------------------------


def test_label_picks_keep_the_labels_apart_and_the_largest_in():
    x = np.linspace(-10.0, 10.0, 25)
    v = np.array([3000.0 + 100 * i for i in range(25)])
    v[7] = 9000.0
    idx = label_picks(x, v, 3.0)
    assert 7 in idx.tolist()
    assert np.all(np.diff(x[idx]) >= 3.0 - 1e-12)  # sorted by x, each pair a width apart


def test_p_max_edge_labels_do_not_overprint():
    """ISO/TR 6336-30 ex. 1: an edge value above the range at each of 25 positions: the labels
    written do not overlap (their drawn boxes are disjoint), and the largest value is one."""
    n = 25
    phi = np.linspace(-10.6, 9.7, n)
    vals = 5000.0 + 2000.0 * np.abs(np.sin(np.arange(n)))
    cycle = NS(
        phi1=np.radians(phi),
        positions=tuple(_position([_pair(0, 1.0, p_int=1000.0 + i, p_edge=vals[i])])
                        for i in range(n)),
    )  # fmt: skip
    fig, ax = plt.subplots(figsize=(6.5, 4))
    plot_p_max(ax, p_max_series(cycle))
    fig.tight_layout()
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(r) for t in ax.texts]
    assert 1 <= len(boxes) < n
    assert f"{vals.max():.0f}" in [t.get_text() for t in ax.texts]
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            assert not boxes[i].overlaps(boxes[j])
    plt.close(fig)


# ---- line_load.png ------------------------------------------------------------------------


def _load_distribution(n: int = 25):
    z = np.linspace(-47.0, 47.0, 16)
    rng = np.random.default_rng(1)
    pos = [NS(force_N=1.0, q_N_per_mm=500.0 * (1 + 0.3 * rng.standard_normal(z.size)),
              usable=i != 3, mesh_stiffness=None if i == 3 else 24.0 + 0.3 * np.sin(i))
           for i in range(n)]  # fmt: skip
    return NS(positions=pos, z_mm=z, face_mm=100.0, normal_force_N=50000.0, k_h_beta=1.045,
              q_mean_N_per_mm=np.full(z.size, 500.0), dz_mm=6.25, c_gamma=24.26)  # fmt: skip


def _line_load_run(n: int = 25):
    status = ["lost" if i == 3 else "ok" for i in range(n)]
    return NS(case=NS(name="iso"), cycle=NS(phi1=np.radians(np.linspace(-10, 10, n)),
              positions=tuple(NS(status=s) for s in status)))  # fmt: skip


def test_line_load_legends_lie_outside_the_axes():
    """The legend of each panel is drawn off its axes (the boxes do not overlap), so no position
    curve is hidden under it; the face panel names positions by a colour bar, not 25 entries."""
    ld, run = _load_distribution(), _line_load_run()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.6))
    cylindrical_output._face_panel(a1, fig, ld, run)
    cylindrical_output._stiffness_panel(a2, ld, run)
    fig.tight_layout()
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    for ax in (a1, a2):
        leg = ax.get_legend()
        assert leg is not None
        assert not leg.get_window_extent(r).overlaps(ax.get_window_extent(r))
    assert len(a1.get_legend().get_texts()) <= 4
    assert any(a.get_ylabel() == "position index" for a in fig.axes)  # the colour bar
    plt.close(fig)


def test_line_load_stiffness_axis_starts_at_zero_and_marks_left_out_positions():
    """A 2 % ripple on an axis from zero, its percentage written in the title; the lost position
    marked (its stiffness is None: at the axis bottom)."""
    ld, run = _load_distribution(), _line_load_run()
    fig, ax = plt.subplots()
    cylindrical_output._stiffness_panel(ax, ld, run)
    assert ax.get_ylim()[0] == 0.0
    assert "ripple" in ax.get_title() and "%" in ax.get_title()
    marks = [ln for ln in ax.lines if ln.get_label().startswith("left out")]
    assert [ln.get_label() for ln in marks] == ["left out: lost (1)"]
    assert np.asarray(marks[0].get_ydata()).tolist() == [0.0]
    plt.close(fig)


def test_ripple_is_peak_to_peak_over_the_mean():
    mean, pct = cylindrical_output.ripple(np.array([24.0, 24.5, np.nan, 23.5]))
    assert mean == pytest.approx(24.0, rel=1e-12)  # exact arithmetic up to round-off
    assert pct == pytest.approx(100.0 / 24.0, rel=1e-12)
    assert cylindrical_output.ripple(np.array([np.nan])) is None
    assert cylindrical_output.stiffness_limits(np.array([24.5, 23.0]))[0] == 0.0


def test_unloaded_pattern_names_line_contacts_and_keeps_point_ellipses(tmp_path, monkeypatch):
    """Fidelity ``tca``'s picture: a spur pair's positions (line contacts) give contact lines
    and a legend entry saying so, no ellipse; a crowned pair's give the paint and the Hertz
    ellipses."""
    from fegear.tca.plots import plot_pattern

    r = NS(pattern_pinion=np.zeros(0), has_contact=np.ones(3, dtype=bool),
           pinion_uv=np.array([[10.0, 0.0]] * 3), paint_mm=0.00632)  # fmt: skip
    bounds = NS(**vars(_BOUNDS), u_name="u (mm)", v_name="v (mm)")
    figs = []
    monkeypatch.setattr(plt.Figure, "savefig", lambda fig, *a, **k: figs.append(fig))
    plot_pattern(r, tmp_path / "a.png", bounds, ellipses=[_ellipse(0.0, 0.2, True)] * 3)
    point = _ellipse(5.0, 1.0)
    point.paint_a_mm = 8.0
    plot_pattern(r, tmp_path / "b.png", bounds, ellipses=[point] * 3)
    line_labels = figs[0].axes[0].get_legend_handles_labels()[1]
    point_labels = figs[1].axes[0].get_legend_handles_labels()[1]
    assert any(t.startswith("line contact at 3 positions") for t in line_labels)
    assert not any(t.startswith(("ellipse", "Hertz")) for t in line_labels)
    assert any(t.startswith("ellipse, paint") for t in point_labels)
    assert any(t.startswith("Hertz") for t in point_labels)
    assert not any(t.startswith("line contact") for t in point_labels)
