"""The scene parameters: one table, the single source of the config schema, defaults, units and labels.

Every entry is a parameter that a study can fix in ``base`` or sweep (grid, zip, cases, Latin hypercube).
Units sit in the names where people type numbers. ``workflow/schemas/config.schema.yaml`` is generated from
this table (``python -m beadsim.schema``) and a test keeps the two in sync.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Param:
    """One scene parameter."""

    name: str
    type: str  # "number", "integer", "string", "boolean"
    default: object
    units: str  # UDUNITS string, "1" for dimensionless, "" for non-numeric
    description: str
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: float | None = None
    enum: tuple = ()
    short: str = ""  # short label used in run ids
    models: tuple = ("reduced", "sph")  # models that read it
    long_name: str = ""

    @property
    def label(self) -> str:
        """Axis label: long name with units."""
        name = self.long_name or self.name
        return f"{name} [{self.units}]" if self.units not in ("", "1") else name


MATERIALS = ("Ti-Gr2", "308LSi")
MODELS = ("reduced", "sph")

PARAMETERS: list[Param] = [
    Param("model", "string", "reduced", "", "bead model: reduced (analytic conduction + capillary cap) or sph "
          "(LAMMPS SPH)", enum=MODELS, short="model"),
    Param("material", "string", "Ti-Gr2", "", "wire and substrate material (Table 2)", enum=MATERIALS, short="mat"),
    Param("beam_power_W", "number", 1000.0, "W", "electron-beam power P", exclusive_minimum=0, maximum=20000,
          short="P", long_name="beam power"),
    Param("beam_efficiency", "number", 0.85, "1", "fraction of the beam power absorbed by the work piece",
          exclusive_minimum=0, maximum=1, short="eta", long_name="beam efficiency"),
    Param("beam_profile", "string", "ring", "", "beam model: ring (scanned circle, time-averaged), scan "
          "(explicit circular scanning at scan_frequency_Hz; SPH only, the reduced model averages it), gaussian "
          "(one static spot of radius beam_spot_radius_mm)", enum=("ring", "scan", "gaussian"), short="beam"),
    Param("scan_diameter_mm", "number", 2.0, "mm", "diameter D of the scanned circle", minimum=0, maximum=20,
          short="D", long_name="scan diameter"),
    Param("scan_frequency_Hz", "number", 800.0, "Hz", "beam scanning frequency f", exclusive_minimum=0,
          maximum=1e5, short="f", long_name="scan frequency"),
    Param("beam_spot_radius_mm", "number", 0.25, "mm", "Gaussian beam spot radius (standard deviation sigma)",
          exclusive_minimum=0, maximum=5, short="sig", long_name="beam spot radius"),
    Param("substrate_speed_mm_s", "number", 5.0, "mm s-1", "substrate travel speed V_s", exclusive_minimum=0,
          maximum=100, short="Vs", long_name="substrate speed"),
    Param("wire_feed_mm_s", "number", 10.0, "mm s-1", "wire feed rate V_w; 0 = a beam-only pass (the SPH scene "
          "then has no wire)", minimum=0, maximum=200, short="Vw",
          long_name="wire feed rate"),
    Param("wire_diameter_mm", "number", 1.2, "mm", "wire diameter d", exclusive_minimum=0, maximum=5, short="d",
          long_name="wire diameter"),
    Param("wire_angle_deg", "number", 45.0, "degree", "wire feed angle alpha from the substrate surface",
          minimum=5, maximum=90, short="alpha", long_name="wire angle"),
    Param("wire_height_mm", "number", 1.5, "mm", "height H of the wire axis above the substrate at the beam "
          "axis", minimum=0, maximum=10, short="H", long_name="wire height"),
    Param("wetting_angle_deg", "number", 0.0, "degree", "equilibrium contact angle of the melt on the solid "
          "substrate (0 = the material's value in materials.yaml); sets how far a bead spreads beyond the melted "
          "width (reduced model) and the adhesion strength (SPH with surface tension)", minimum=0, maximum=150,
          short="wet", long_name="wetting angle"),
    Param("preheat_K", "number", 300.0, "K", "initial (preheat) temperature of substrate and wire",
          minimum=1, maximum=1500, short="T0", long_name="preheat temperature"),
    Param("volumetric_heat_W", "number", 0.0, "W", "extra volumetric heat (induction heating) spread over the "
          "substrate; the reduced model ignores it", minimum=0, maximum=20000, short="Qv",
          long_name="volumetric heat"),
    Param("substrate_length_mm", "number", 20.0, "mm", "substrate length along travel", exclusive_minimum=0,
          maximum=200, short="Ls", long_name="substrate length"),
    Param("substrate_width_mm", "number", 10.0, "mm", "substrate width across travel", exclusive_minimum=0,
          maximum=200, short="Ws", long_name="substrate width"),
    Param("substrate_thickness_mm", "number", 5.0, "mm", "substrate thickness", exclusive_minimum=0,
          maximum=100, short="Hs", long_name="substrate thickness"),
    Param("resolution_mm", "number", 0.3, "mm", "SPH particle spacing dx (the reduced model's grid uses "
          "dx/4)", minimum=0.02, maximum=2, short="dx", long_name="particle spacing"),
    Param("sim_time_s", "number", 2.0, "s", "process time to simulate (SPH; may stop earlier at steady state)",
          exclusive_minimum=0, maximum=60, short="t", models=("sph",), long_name="process time"),
]


def _sph_parameters() -> list[Param]:
    try:
        from beadsim.sph.params import SPH_PARAMETERS
    except ImportError:
        return []
    return list(SPH_PARAMETERS)


def all_parameters() -> dict[str, Param]:
    """All scene parameters by name (common ones first, then SPH numerics)."""
    table = {p.name: p for p in PARAMETERS}
    for p in _sph_parameters():
        if p.name in table:
            raise ValueError(f"parameter {p.name} defined twice")
        table[p.name] = p
    return table


def defaults() -> dict:
    """Default value of every parameter."""
    return {name: p.default for name, p in all_parameters().items()}
