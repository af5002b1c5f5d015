"""Speed levers change the cost, not the answer.

``fluid_pairs_only`` drops the SPH pressure/viscosity term from pairs of frozen particles (zero cutoff). Such pairs move
rigidly (equal velocities: their density and energy increments are exactly zero) and their forces are zeroed, so
the answer changes only through pairs of frozen particles with different velocities (the fed wire against the
substrate) and through particles that melt within a chunk (they feel the melt before their type switches). The
trajectories then separate as those of 1 and 2 MPI ranks do (test_mpi), so the same tolerances apply.
"""

import pytest
import xarray as xr

from beadsim.sph.driver import fluid_pair_types, run_case
from beadsim.sph.scene import FLUID_TYPES, N_TYPES

from test_bead import small_case


def test_fluid_pair_types_cover_every_pair_with_melt():
    """Every type pair gets coefficients (a pair left out runs on a stale skip list when types change); the
    term acts exactly on the pairs with a liquid or falling particle."""
    pairs = {(int(i), int(j)): on for i, j, on in fluid_pair_types(True)}
    assert len(pairs) == N_TYPES * (N_TYPES + 1) // 2
    for (i, j), on in pairs.items():
        assert on == (i in FLUID_TYPES or j in FLUID_TYPES), (i, j)
    assert fluid_pair_types(False) == [("*", "*", True)]
    # per-type coefficients (wetting pressure balance): every pair listed; with fluid_pairs_only as before
    every = fluid_pair_types(False, per_type=True)
    assert len(every) == N_TYPES * (N_TYPES + 1) // 2 and all(on for _, _, on in every)
    assert fluid_pair_types(True, per_type=True) == fluid_pair_types(True)


@pytest.mark.slow
def test_fluid_pairs_only_keeps_the_answer(tmp_path):
    runs = {}
    for on in (True, False):
        out = tmp_path / f"fpo_{on}"
        runs[on] = run_case(small_case(sim_time_s=0.25, fluid_pairs_only=on), out)
        deck = (out / "deck.in").read_text()
        assert ("pair_coeff * * sph/taitwater" in deck) is not on
        frozen_pair = next((line for line in deck.splitlines() if line.startswith("pair_coeff 1 1 sph/taitwater")), "")
        assert frozen_pair.endswith(" 0") is on  # frozen-frozen: zero cutoff
    on, off = runs[True], runs[False]
    assert on["n_steps"] == off["n_steps"] and on["n_particles"] == off["n_particles"]
    assert on["energy_in_J"] == pytest.approx(off["energy_in_J"], rel=1e-12)
    assert abs(on["energy_balance_error"]) < 1e-3
    for key in ("evaporated_energy_J", "boundary_heat_loss_J"):
        assert on[key] == pytest.approx(off[key], rel=0.10), key
    series = [xr.load_dataset(tmp_path / f"fpo_{flag}" / "timeseries.nc") for flag in (True, False)]
    late = [s["n_liquid"].where(s["t"] > 0.125).mean().item() for s in series]
    assert late[0] == pytest.approx(late[1], rel=0.10)
    assert series[0]["E_internal"][-1].item() == pytest.approx(series[1]["E_internal"][-1].item(), rel=0.01)
