"""Mesh-order amplitudes of a TE series over one mesh cycle (fegear.ltca.harmonics)."""

import numpy as np
import pytest

from fegear.ltca.harmonics import mesh_orders


def test_amplitudes_of_a_sum_of_mesh_harmonics():
    n = 25
    i = np.arange(n)
    te = -3.0 + 2.0 * np.sin(2 * np.pi * i / n + 0.3) + 0.5 * np.cos(4 * np.pi * i / n)
    te += 0.1 * np.sin(6 * np.pi * i / n - 1.0)
    m = mesh_orders(te)
    # the DFT of exact harmonics below Nyquist: round-off
    assert m.amplitude_arcsec == pytest.approx((2.0, 0.5, 0.1), abs=1e-12)
    assert m.reason == ""


def test_too_few_or_excluded_positions_give_no_amplitude():
    m = mesh_orders(np.sin(2 * np.pi * np.arange(5) / 5))
    assert m.amplitude_arcsec[0] == pytest.approx(1.0, abs=1e-12)
    assert m.amplitude_arcsec[2] is None and "n > 2k" in m.reason  # order 3 needs 7 positions
    m = mesh_orders(np.zeros(9), usable=[True] * 6 + [False] * 3)  # 6 of 9 < 75 %
    assert m.amplitude_arcsec == (None, None, None) and "left out" in m.reason
    assert (m.positions_used, m.positions) == (6, 9)


def _series(n):
    i = np.arange(n)
    return (
        -3.0
        + 2.0 * np.sin(2 * np.pi * i / n + 0.3)
        + 0.5 * np.cos(4 * np.pi * i / n)
        + (0.1 * np.sin(6 * np.pi * i / n - 1.0))
    )


@pytest.mark.parametrize("left_out", [[0], [12], [3, 17], [5, 6]])
def test_positions_left_out_are_fitted_around(left_out):
    """A cycle with a degenerate hand-over position keeps its harmonics: the least-squares
    Fourier fit on the positions left recovers a series of mesh orders 0-3 exactly (it lies in
    the fitted space; round-off), and says how many positions it used."""
    n = 25
    usable = np.ones(n, bool)
    usable[left_out] = False
    te = _series(n)
    te[~usable] = 1e3  # whatever a left-out position holds is not read
    m = mesh_orders(te, usable)
    assert m.amplitude_arcsec == pytest.approx((2.0, 0.5, 0.1), abs=1e-9)
    assert m.reason == "" and (m.positions_used, m.positions) == (n - len(left_out), n)


def test_a_gap_in_a_rich_series_moves_the_orders_by_at_most_the_leakage():
    """A series with content at every order (random), one position of 25 left out: the fit of
    the other 24 (at most K = 11 orders) cannot represent the order-12 content, which leaks
    into the fitted orders; each first order moves from the full cycle's DFT value by at most
    MAX_COND times that content (the bound the conditioning limit is there for)."""
    rng = np.random.default_rng(3)
    n = 25
    te = rng.normal(size=n)
    full = mesh_orders(te)
    usable = np.ones(n, bool)
    usable[7] = False
    gappy = mesh_orders(te, usable)
    assert gappy.positions_used == 24
    top = 2.0 * abs(np.fft.rfft(te)[12]) / n
    for a, b in zip(gappy.amplitude_arcsec, full.amplitude_arcsec, strict=True):
        assert abs(a - b) <= 10.0 * top + 1e-12  # MAX_COND bounds the leakage of the rest
