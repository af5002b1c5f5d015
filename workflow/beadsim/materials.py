"""Material properties (Table 2 plus literature values) in SI units."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import yaml

DEFAULT_FILE = Path(__file__).resolve().parents[2] / "config" / "materials.yaml"


@dataclass(frozen=True)
class Material:
    """Constant-property material (SI units)."""

    key: str
    name: str
    rho: float  # kg m-3
    T_melt: float  # K
    k: float  # W m-1 K-1
    cp: float  # J kg-1 K-1
    mu: float  # Pa s
    latent_heat: float  # J kg-1
    T_boil: float  # K
    surface_tension: float  # N m-1
    contact_angle_deg: float  # degree
    backscatter: float = float("nan")  # electron backscatter coefficient at normal incidence (optional)

    @property
    def diffusivity(self) -> float:
        """Thermal diffusivity k / (rho cp), m2 s-1."""
        return self.k / (self.rho * self.cp)

    @property
    def nu(self) -> float:
        """Kinematic viscosity mu / rho, m2 s-1."""
        return self.mu / self.rho


_FIELDS = {
    "rho": "density",
    "T_melt": "melting_temperature",
    "k": "thermal_conductivity",
    "cp": "heat_capacity",
    "mu": "dynamic_viscosity",
    "latent_heat": "latent_heat",
    "T_boil": "boiling_temperature",
    "surface_tension": "surface_tension",
    "contact_angle_deg": "contact_angle",
}


def load_materials(path: str | Path | None = None) -> dict[str, dict]:
    """Read the raw materials file (a dict keyed by material id)."""
    with open(path or DEFAULT_FILE) as fh:
        return yaml.safe_load(fh)


def get_material(key: str, path: str | Path | None = None, overrides: dict | None = None) -> Material:
    """Return one material; ``overrides`` maps Material field names to values (e.g. {"k": 20.0}).

    Raises
    ------
    KeyError
        If ``key`` is not in the file; the message lists the known materials.
    """
    table = load_materials(path)
    if key not in table:
        raise KeyError(f"material {key!r} is not defined; known materials: {sorted(table)}")
    entry = table[key]
    values = {f: float(entry[src]["value"]) for f, src in _FIELDS.items()}
    if "backscatter_coefficient" in entry:  # optional: only beam_incidence oblique needs it
        values["backscatter"] = float(entry["backscatter_coefficient"]["value"])
    values.update(overrides or {})
    return Material(key=key, name=entry.get("name", key), **values)
