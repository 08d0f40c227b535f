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
    m = mesh_orders(np.zeros(9), usable=[True] * 8 + [False])
    assert m.amplitude_arcsec == (None, None, None) and "left out" in m.reason
