"""Measured-bead mass balance and the error table."""

import math

import pytest

from beadsim.compare import measured_mass_balance, wire_supply_area
from beadsim.reduced import cap_area


def test_cap_area_semicircle_and_shallow_limit():
    assert cap_area(2.0, 1.0) == pytest.approx(math.pi / 2)
    # A shallow cap tends to a parabola, 2/3 w h.
    assert cap_area(4.0, 0.01) == pytest.approx(2 / 3 * 4.0 * 0.01, rel=1e-4)


def test_table1_mass_balance(experiments):
    """Mode 1 holds the metal the wire fed; modes 2 and 3 hold 50-75 % of it (the paper's data)."""
    mb = measured_mass_balance(experiments).set_index("mode")
    assert mb.loc[1, "wire_supply_area_mm2"] == pytest.approx(wire_supply_area(1.2, 10, 5))
    assert mb.loc[1, "consistent"]
    assert 0.95 < mb.loc[1, "ratio_cap"] < 1.1
    assert not mb.loc[2, "consistent"] and not mb.loc[3, "consistent"]
    assert mb.loc[2, "ratio_cap"] == pytest.approx(0.75, abs=0.02)
    assert mb.loc[3, "ratio_cap"] == pytest.approx(0.51, abs=0.02)
    # A 3.6 mm wide cap must be ~1.29 mm tall to hold the fed 3.39 mm2.
    assert cap_area(3.6, mb.loc[2, "height_if_width_right_mm"]) == pytest.approx(3.393, rel=1e-3)
