"""Per-run metrics: names, units (UDUNITS) and long names, shared by every model.

A model returns a dict whose keys are names from this table (missing keys become NaN in the dataset).
"""

from __future__ import annotations


def _run_stats(mean_key: str, sd_key: str, units: str, what: str, note: str = "") -> dict[str, tuple[str, str]]:
    """Entries for a per-section value's mean and standard deviation over the cross-sections since the wire's
    metal arrived (SPH window; ``driver.RUN_MEANS``), ``note`` added to the mean's."""
    since = "the cross-sections since the wire's metal arrived (SPH window"
    return {mean_key: (units, f"{what}, mean of {since}{'; ' + note if note else ''})"),
            sd_key: (units, f"{what}, standard deviation of {since})")}


METRICS: dict[str, tuple[str, str]] = {
    # name: (units, long_name)
    "bead_width_mm": ("mm", "bead width"),
    "bead_height_mm": ("mm", "bead height above substrate"),
    "bead_area_mm2": ("mm2", "bead cross-section area above substrate"),
    "bead_width_sd_mm": ("mm", "bead width, standard deviation of the averaged cross-sections (SPH window)"),
    "bead_height_sd_mm": ("mm", "bead height, standard deviation of the averaged cross-sections (SPH window)"),
    "mass_balance_sd": ("1", "mass balance ratio, standard deviation of the averaged cross-sections (SPH window)"),
    "bead_samples": ("1", "bead cross-sections averaged into the bead metrics (SPH moving window)"),
    **_run_stats("bead_width_run_mean_mm", "bead_width_run_sd_mm", "mm", "bead width",
                 "over the humps of a humping bead"),
    **_run_stats("bead_height_run_mean_mm", "bead_height_run_sd_mm", "mm", "bead height"),
    "bead_height_mass_mm": ("mm", "bead height from the mass per column: peak of the (1, 2, 1) / 4 running mean "
                            "of the particles counted per column at the lattice's density (SPH; mean of the "
                            "averaged cross-sections in a window run)"),
    **_run_stats("bead_height_mass_run_mean_mm", "bead_height_mass_run_sd_mm", "mm",
                 "bead height from the mass per column"),
    "bead_width_mass_mm": ("mm", "bead width from the mass per column: where the particles counted per column "
                           "at the lattice's density reach half a spacing, edges interpolated (SPH; mean of the "
                           "averaged cross-sections in a window run)"),
    **_run_stats("bead_width_mass_run_mean_mm", "bead_width_mass_run_sd_mm", "mm",
                 "bead width from the mass per column"),
    **_run_stats("mass_balance_run_mean", "mass_balance_run_sd", "1", "mass balance ratio"),
    "bead_run_from_s": ("s", "time of the first cross-section carrying the wire's metal (mass balance within "
                        "steady_tolerance of 1; SPH window)"),
    "bead_run_sections": ("1", "cross-sections in the run means (SPH window)"),
    "bead_top_phase": ("1", "where the bead's column tops sit between the plate's layers continued upwards, "
                       "circular mean in spacings (0: on a layer; SPH)"),
    "bead_top_order": ("1", "how closely the bead's column tops keep one phase: 1 stacked on one phase of the "
                       "layers, near 0 at every height (resultant length; SPH; which reading of the measured "
                       "bead it compares with: registered near 1, random near 0)"),
    "aspect_ratio": ("1", "bead height / width"),
    "contact_angle_deg": ("degree", "bead contact angle"),
    "penetration_depth_mm": ("mm", "remelt depth into substrate"),
    "fusion_width_mm": ("mm", "width of the fused (ever-molten) top surface, the deposit's top included"),
    "plate_fusion_width_mm": ("mm", "width of the plate's own top surface that melted (the deposit left out; SPH)"),
    **_run_stats("plate_fusion_width_run_mean_mm", "plate_fusion_width_run_sd_mm", "mm",
                 "width of the plate's surface that melted"),
    "toe_overhang_mm": ("mm", "how far the bead's metal (by mass, half a spacing thick) reaches past the melted "
                        "plate on each side: (bead_width_mass - plate_fusion_width) / 2; > 0: the toes lie on "
                        "plate whose particles never melted (their interface with the melt may be at the melting "
                        "point; SPH)"),
    **_run_stats("toe_overhang_run_mean_mm", "toe_overhang_run_sd_mm", "mm", "toe overhang"),
    "pool_length_mm": ("mm", "melt pool length"),
    "pool_width_mm": ("mm", "melt pool width"),
    "pool_depth_mm": ("mm", "melt pool depth"),
    "pool_volume_mm3": ("mm3", "melt pool volume"),
    "pool_length_sd_mm": ("mm", "melt pool length, standard deviation over the last 0.25 s (SPH)"),
    "pool_width_sd_mm": ("mm", "melt pool width, standard deviation over the last 0.25 s (SPH)"),
    "pool_depth_sd_mm": ("mm", "melt pool depth, standard deviation over the last 0.25 s (SPH)"),
    "pool_volume_sd_mm3": ("mm3", "melt pool volume, standard deviation over the last 0.25 s (SPH)"),
    "pool_samples": ("1", "pool snapshots averaged into the pool metrics (SPH moving window)"),
    "T_max_K": ("K", "maximum temperature"),
    "melt_speed_max_m_s": ("m s-1", "maximum melt speed"),
    "wire_supply_area_mm2": ("mm2", "wire area fed per unit travel"),
    "mass_balance_ratio": ("1", "bead area / wire supply area"),
    "bead_packing": ("1", "bead area above the substrate / the wire metal in the same sections at the "
                     "lattice's density (SPH; ~1 for a dense deposit, above 1 for a loose one)"),
    "wire_melt_power_W": ("W", "power needed to melt the wire"),
    "absorbed_power_W": ("W", "absorbed beam power"),
    "energy_in_J": ("J", "beam energy delivered"),
    "energy_balance_error": ("1", "energy balance error (relative to energy in)"),
    "evaporated_energy_J": ("J", "energy removed by the boiling cap"),
    "boundary_heat_loss_J": ("J", "heat leaving through domain boundaries"),
    "surface_work_J": ("J", "work of the height-function surface forces on the melt (SPH, surface_force "
                       "height_function; booked in the energy ledger)"),
    "n_particles": ("1", "number of particles"),
    "dx_mm": ("mm", "particle spacing"),
    "dt_s": ("s", "time step"),
    "sound_speed_used_m_s": ("m s-1", "artificial sound speed used"),
    "n_steps": ("1", "time steps"),
    "simulated_time_s": ("s", "simulated process time"),
    "steady_state_time_s": ("s", "time steady state was detected"),
    "particle_steps_per_s": ("s-1", "particle-steps per second"),
    "python_time_share": ("1", "share of wall time outside LAMMPS"),
    "python_time_share_bead_checks": ("1", "share of wall time spent in bead cross-section checks (window)"),
    "mpi_ranks": ("1", "MPI ranks of the run"),
    "wall_time_s": ("s", "wall time of the model"),
    "density_min": ("1", "minimum liquid density / rho0"),
    "density_max": ("1", "maximum liquid density / rho0"),
    "liquid_packing": ("1", "kernel fill of the melt / lattice's, 90th percentile over the last 0.25 s (SPH; "
                       "well below 1: expanded, or a melt without a kernel-wide interior)"),
    "spatter_particles": ("1", "fluid particles deleted after leaving the modelled block"),
    "wire_feed_start_s": ("s", "process time the wire feed started (NaN: never)"),
    "wire_meltback_mm": ("mm", "mean distance the solid wire's tip melted back along its axis from the nominal "
                         "tip (SPH; second half of the run)"),
    "wire_feed_end_share": ("1", "share of samples (second half of the run) in which the wire melted back to the "
                            "feed end of the modelled wire: above 0 the melt-back is bounded by wire_length_mm"),
    "beam_share_solid_wire": ("1", "share of the absorbed beam energy that landed on solid wire (SPH; second "
                              "half of the run)"),
    "beam_share_wire_melt": ("1", "share of the absorbed beam energy that landed on melt from the wire, on the "
                             "wire's tip or in the pool (SPH; second half of the run)"),
    "held_melt_share": ("1", "share of the melt held still where it touches cold plate, mean over the second "
                        "half of the run (SPH, contact_freeze; NaN without it)"),
    "wire_released_particles": ("1", "unmelted wire particles cut off from the fed wire (fell free)"),
    "wire_landed_particles": ("1", "released wire particles that landed on solid before melting"),
}

# String-valued outputs (not numbers).
TEXT_OUTPUTS = {"regime": "process regime", "status": "run status", "reason": "failure reason"}
