"""SPH numerics parameters (read only by the LAMMPS SPH model).

The scene itself (beam, wire, substrate, ``resolution_mm``, ``sim_time_s``) is described by
:data:`beadsim.parameters.PARAMETERS`; this table adds the knobs of the numerical method. Options that go beyond
the paper (latent heat, boiling cap, far-field boundary, surface tension, density filter) are switchable here.
"""

from __future__ import annotations

from beadsim.parameters import Param

_SPH = ("sph",)

SPH_PARAMETERS: list[Param] = [
    Param("dt_factor", "number", 1.0, "1", "time step as a multiple of the automatic limit (min of acoustic "
          "CFL, viscous eq. 22, thermal, gravity and capillary limits)", exclusive_minimum=0, maximum=20,
          short="dtf", models=_SPH, long_name="time-step factor"),
    Param("sound_speed_m_s", "number", 0.0, "m s-1", "artificial sound speed c0 of the Tait equation of state; "
          "0 = automatic (10 x the largest expected melt speed, at least sqrt(g H / 0.01))", minimum=0,
          maximum=1000, short="c0", models=_SPH, long_name="sound speed"),
    Param("viscosity_model", "string", "artificial", "", "viscous term: artificial (Monaghan, sph/taitwater; "
          "held in tests) or morris (physical viscosity, eq. 19-20 of the paper; sph/taitwater/morris)",
          enum=("artificial", "morris"), short="visc", models=_SPH),
    Param("artificial_viscosity", "number", 0.1, "1", "Monaghan artificial viscosity alpha (viscosity_model "
          "artificial)", minimum=0, maximum=10, short="av", models=_SPH, long_name="artificial viscosity"),
    Param("kernel_cutoff_factor", "number", 2.5, "1", "kernel cutoff h as a multiple of the particle spacing "
          "(Lucy kernel)", minimum=1.2, maximum=5, short="hdx", models=_SPH, long_name="kernel cutoff / dx"),
    Param("fluid_pairs_only", "boolean", True, "", "compute the SPH pressure and viscosity pair term only for "
          "pairs with a liquid or falling particle; pairs of frozen particles (which move rigidly, have their "
          "forces zeroed and their densities reset) get heat conduction only. A speed lever: false computes the "
          "term for every pair (the cost before 2026-11-22; the same answer within run-to-run scatter)", short="fpo", models=_SPH,
          long_name="fluid pairs only"),
    Param("surface_tension", "boolean", False, "", "add a pairwise cohesive (surface tension) force between "
          "liquid particles (beadsim.sph.tension); off in the paper", short="st", models=_SPH),
    Param("surface_force", "string", "pairwise", "", "how surface_tension acts: pairwise (a cohesive pair force "
          "between melt particles; verified in drop tests, but it makes the melt a particle crystal with a yield "
          "stress of ~0.1-0.6 sigma / dx) or height_function (a plain SPH melt with the Laplace force "
          "sigma kappa on the top particle of each column, kappa from the column height map, and a contact-line "
          "pull sigma (1 - cos theta) set by wetting_angle_deg; beadsim.sph.heightfn)",
          enum=("pairwise", "height_function"), short="sf", models=_SPH),
    Param("height_function_smoothing", "number", 1.0, "1", "surface_force height_function: Gaussian smoothing "
          "of the column height map before its curvature is taken, in columns (0 = none)", minimum=0,
          maximum=5, short="hfs", models=_SPH, long_name="height-function smoothing"),
    Param("height_function_cohesion", "number", 0.0, "1", "surface_force height_function: share of sigma "
          "carried by the pairwise cohesion beside the height-function force (which carries the rest); the "
          "column force holds no particle to its neighbours, the cohesion does", minimum=0, maximum=1,
          short="hfc", models=_SPH, long_name="height-function cohesion share"),
    Param("wetting_pressure_balance", "boolean", False, "", "surface tension with a wetting ratio below 1: give "
          "the solid particle types a Tait reference density at which their pressure balances the weaker "
          "liquid-solid cohesion across the interface ((2 r - 1) times the liquid's background pressure; "
          "tension.CohesionModel.solid_tait_rho0), so that the melt beside solid does not expand; no effect at "
          "ratio 1", short="wpb", models=_SPH, long_name="wetting pressure balance"),
    Param("plate_wetting_ratio", "number", 0.0, "1", "surface tension (pairwise): cohesion between the melt and "
          "the plate that never melted, as a ratio s_lp / s_ll (0: as between the melt and every other solid, "
          "set by wetting_angle_deg). The paper: where the beam melts the substrate's surface 'the best wetting "
          "takes place'; a ratio below that of wetting_angle_deg wets the melted metal better than the cold "
          "plate (ridges: 0.5 / 0.6 / 0.8 give 85 / 75 / 52 degree, tension.py)", minimum=0, maximum=1.3,
          short="pwr", models=_SPH, long_name="plate wetting ratio"),
    Param("contact_freeze", "boolean", False, "", "hold a melt particle still (moving with the plate) while it "
          "touches plate that never melted (within 1.25 dx) and the contact temperature of the pair, the mean of "
          "the two temperatures (the interface temperature of two like bodies put in contact), is below the "
          "melting point: the melt freezes where it meets cold plate, so a contact line running out over the "
          "plate stops (arrest by solidification at the contact line); it flows again once the plate beneath "
          "warms. A stand-in for the solid skin dx cannot resolve; the particle keeps its energy and counts as "
          "melt. A probe of what sets the SPH beads' width, beside plate_wetting_ratio; off in the paper",
          short="cfz", models=_SPH, long_name="contact freeze"),
    Param("latent_heat", "boolean", False, "", "latent heat of fusion as an effective heat capacity over "
          "mushy_range_K above T_melt; off to match the paper", short="lh", models=_SPH),
    Param("mushy_range_K", "number", 50.0, "K", "temperature range over which the latent heat is released "
          "(latent_heat true)", exclusive_minimum=0, maximum=1000, short="dTm", models=_SPH,
          long_name="mushy range"),
    Param("melt_conductivity_factor", "number", 1.0, "1", "multiplies the thermal conductivity between liquid "
          "particles, standing for the heat the Marangoni flow carries through a real pool (an enhanced-"
          "conductivity model, beyond the paper; weld-pool models use 2-10); 1 = the paper's conduction",
          minimum=1, maximum=50, short="fk", models=_SPH, long_name="melt conductivity factor"),
    Param("melt_interface_conductivity", "string", "solid", "", "conductivity of liquid-solid particle pairs when "
          "melt_conductivity_factor > 1: solid (the solid's, as in the paper) or harmonic (harmonic mean of the "
          "enhanced melt and the solid: 2f/(1+f) times the solid's, the series conductance of the two sides)",
          enum=("solid", "harmonic"), short="fki", models=_SPH),
    Param("temperature_cap", "boolean", True, "", "cap temperatures at the boiling point and count the excess "
          "energy as evaporation", short="cap", models=_SPH),
    Param("thermal_boundary", "string", "farfield", "", "side/bottom faces of the modelled block that cut the "
          "plate: farfield (flux k (T-T0)/sqrt(pi a t) into the semi-infinite rest of the plate), insulated "
          "(zero flux, as in the paper), fixed (held at the preheat temperature). Faces that are real plate "
          "faces are insulated in every case", enum=("farfield", "insulated", "fixed"), short="bc",
          models=_SPH),
    Param("domain", "string", "auto", "", "modelled substrate block: auto (fixed block sized from the case: "
          "travel, scan diameter and domain_margin_mm, never larger than the plate), plate (the whole "
          "substrate_*_mm plate) or window (a block moving with the beam, sized from the thermal length; "
          "substrate enters cold at the front, the bead leaves at the back)", enum=("auto", "plate", "window"),
          short="dom", models=_SPH),
    Param("window_thermal_lengths", "number", 3.0, "1", "domain window: margin ahead of and beside the beam "
          "footprint in thermal lengths a / V_s", minimum=0.25, maximum=20, short="wL", models=_SPH,
          long_name="window margin / thermal length"),
    Param("window_bead_mm", "number", 1.5, "mm", "domain window: length of solid bead kept behind the melt "
          "pool (the cross-section is averaged over it)", minimum=0.2, maximum=20, short="wB", models=_SPH,
          long_name="window bead length"),
    Param("bead_sections", "integer", 3, "1", "domain window: bead cross-sections (taken every 0.05 s) whose "
          "mean height profile, mass balance, penetration and fused width make the final bead; more than three "
          "average a bead that humps or varies over a longer stretch (stop_at_steady_state then runs on until "
          "that many sections are steady ones: the three that made it steady and those after)", minimum=1,
          maximum=200, short="nB", models=_SPH, long_name="bead sections averaged"),
    Param("domain_margin_mm", "number", 3.0, "mm", "margin of the auto block around the scanned track and the "
          "wire", minimum=0.5, maximum=50, short="marg", models=_SPH, long_name="domain margin"),
    Param("domain_depth_mm", "number", 3.0, "mm", "thickness of the auto block (at most the plate thickness)",
          exclusive_minimum=0, maximum=100, short="dep", models=_SPH, long_name="domain depth"),
    Param("wire_length_mm", "number", 3.0, "mm", "length of wire modelled from its tip to the feed end where "
          "new slices enter", exclusive_minimum=0, maximum=50, short="Lw", models=_SPH,
          long_name="modelled wire length"),
    Param("wire_feed_start", "string", "immediate", "", "when the wire feed starts: immediate (at t = 0, as in "
          "the paper) or pool (once the pool where the wire tip will land holds a wire cross-section of melt, as "
          "an operator starts the feed on a formed pool; the wire waits still above it until then). A cold wire pushed into cold "
          "metal stubs: a wide scan ring leaves the tip unheated (mode 3, D 3 mm)", enum=("immediate", "pool"),
          short="wfs", models=_SPH, long_name="wire feed start"),
    Param("wire_packing", "string", "stretched", "", "how the wire's particles carry the "
          "nominal wire mass: stretched (full grid slices spaced more than dx apart along the axis: +27 % at "
          "d 1.2 mm, dx 0.4 mm; its melt is under-packed) or lattice (slices dx apart holding on average as "
          "many grid points as the nominal area: a lattice-packed wire of slightly irregular section)",
          enum=("stretched", "lattice"), short="wpk", models=_SPH, long_name="wire packing"),
    Param("wire_detach", "string", "fall", "", "unmelted wire cut off from the fed wire by the beam (a scan ring "
          "wider than the wire crosses it above the tip): fall (no longer fed; it falls and moves with the melt "
          "under SPH forces and gravity until it melts, or until it touches solid substrate or bead, where it "
          "stays as solid moving with the substrate until it melts) or rigid (fed on with the wire, the behaviour before "
          "2026-11, which pushes the piece into the substrate)", enum=("fall", "rigid"), short="wdet",
          models=_SPH, long_name="detached wire"),
    Param("beam_incidence", "string", "flat", "", "beam absorption against the surface slope: flat (every "
          "column absorbs its share, as in the paper) or oblique (a column whose top slopes at angle theta absorbs "
          "(1 - eta(theta)) / (1 - eta0) of it, eta(theta) = 0.891 (eta0 / 0.891)^cos(theta) the electron "
          "backscatter (Arnal et al. 1969), eta0 the material's backscatter_coefficient: 0.85 at 45 deg, so the "
          "round wire and drops absorb less than the flat pool; the rest is backscattered and booked)",
          enum=("flat", "oblique"), short="inc", models=_SPH),
    Param("beam_layers", "integer", 2, "1", "particle layers below the top of each column seen from above "
          "that share the beam energy of that column", minimum=1, maximum=10, short="bl", models=_SPH),
    Param("shepard_interval", "integer", 50, "1", "steps between Shepard density filters on the liquid "
          "(0 = never); not applied with surface_tension, where it lets the cohesive liquid expand", minimum=0, maximum=100000, short="shep", models=_SPH),
    Param("solid_density_reset", "boolean", True, "", "reset the density of solid particles (frozen, and "
          "falling cut-off wire) to rho0 every chunk", short="sdr", models=_SPH),
    Param("resolidified_density", "string", "rho0", "", "density the reset gives particles that melted and "
          "froze again: rho0 (as the never-melted solid) or freeze (the continuity density each had when it "
          "last froze, so that melt which expanded before freezing remelts at its own density instead of "
          "being refilled to rho0 at every freeze-melt cycle)", enum=("rho0", "freeze"), short="rsd",
          models=_SPH),
    Param("loose_melt_ceiling", "boolean", False, "", "surface tension: cap the density of loosely packed "
          "melt (mean distance to its three nearest particles above dx) at what its packing allows, so that "
          "the cohesion compacts it (driver.loose_density_ceiling); without it melt spread at ~1.2 dx with its "
          "continuity density at rho0 feels no restoring force and the bead stays loose", short="lmc",
          models=_SPH, long_name="loose-melt density ceiling"),
    Param("loose_melt_d3", "number", 1.0, "1", "loose_melt_ceiling: the mean distance to the three nearest "
          "particles (in dx) above which melt counts as loose; its ceiling is rho0 (this / d3)^3",
          minimum=0.8, maximum=1.5, short="lmd", models=_SPH, long_name="loose-melt threshold / dx"),
    Param("loose_melt_smoothing", "number", 0.0, "1", "loose_melt_ceiling: radius (in dx) over which that "
          "distance is averaged before the comparison, so that a loose region is capped and the tail of a "
          "dense liquid's distribution is not; 0 = each particle's own distance, and compressed particles are "
          "capped at rho0 (threshold / d3)^3 too (the first form of the ceiling)", minimum=0, maximum=2,
          short="lms", models=_SPH, long_name="loose-melt smoothing radius / dx"),
    Param("stop_at_steady_state", "boolean", False, "", "stop before sim_time_s once the melt count and pool "
          "length are steady within steady_tolerance over two 0.2 s windows (in the window domain also the last "
          "three bead sections' mass balance within it of 1, and bead_sections steady sections to average); a "
          "humping bead can pass in a quiet spell (mode 1 with plate_wetting_ratio 0.25: at 3.15 s, a hump from "
          "3.6 s)",
          short="ss", models=_SPH),
    Param("steady_tolerance", "number", 0.05, "1", "relative change of the steady-state criteria allowed "
          "between two successive averaging windows", exclusive_minimum=0, maximum=1, short="sstol",
          models=_SPH, long_name="steady-state tolerance"),
    Param("chunk_steps", "integer", 10, "1", "time steps per LAMMPS run chunk (beam deposit, phase update and "
          "watchdog between chunks)", minimum=1, maximum=10000, short="chunk", models=_SPH),
    Param("dump_interval_s", "number", 0.05, "s", "process time between particle dumps", exclusive_minimum=0,
          maximum=60, short="dump", models=_SPH, long_name="dump interval"),
    Param("restart_interval_s", "number", 0.25, "s", "process time between restart checkpoints",
          exclusive_minimum=0, maximum=60, short="rst", models=_SPH, long_name="restart interval"),
    Param("continue_from", "string", "", "", "run id of a case in the same study whose last checkpoint this run "
          "continues (to its own sim_time_s) instead of starting at t = 0: a study run on to a longer time "
          "without repeating what it has. The source's parameters must be this run's except sim_time_s (smaller "
          "there) and stop_at_steady_state, with domain window or plate (auto sizes the block from sim_time_s); "
          "the workflow runs the source first. The run folder gets the source's dumps, deck and series, so it "
          "holds the whole history, and result.json names the source under continued_from; \"\" starts at "
          "t = 0", short="cont", models=_SPH, long_name="continued from"),
    Param("density_tolerance", "number", 0.2, "1", "watchdog: fail when the liquid density leaves "
          "[1 - tol, 1 + tol] rho0", exclusive_minimum=0, maximum=1, short="rtol", models=_SPH),
    Param("speed_limit_m_s", "number", 0.0, "m s-1", "watchdog: fail above this particle speed; 0 = half the "
          "liquid's sound speed (c0; with surface tension that of the shifted Tait liquid, c0 (rho / rho0')^3)",
          minimum=0, maximum=1000, short="vlim", models=_SPH),
    Param("spatter_limit", "integer", 10, "1", "watchdog: fluid particles that may leave the modelled block "
          "(droplets skating off over the cold substrate; deleted, their energy kept in the ledger) before the "
          "run fails", minimum=0, maximum=100000, short="splim", models=_SPH, long_name="spatter limit"),
    Param("energy_tolerance", "number", 0.05, "1", "watchdog: fail when the energy balance error exceeds this "
          "fraction of the beam energy delivered", exclusive_minimum=0, maximum=1, short="etol", models=_SPH),
]
