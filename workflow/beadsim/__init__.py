"""beadsim: electron-beam wire-feed deposition studies (reduced model and LAMMPS SPH)."""

__version__ = "0.1.0"
