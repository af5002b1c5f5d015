"""Provenance: which code, which LAMMPS, which parameters made a result."""

from __future__ import annotations

import datetime as _dt
import functools
import platform
import subprocess
from pathlib import Path

import beadsim

ROOT = Path(__file__).resolve().parents[2]


@functools.cache
def git_commit() -> str:
    """Commit of the code (with '-dirty' if the work tree has changes), 'unknown' outside a git checkout."""
    try:
        rev = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True,
                             check=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return rev + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def lammps_version_or_none() -> str:
    """LAMMPS version string, or 'not installed'."""
    try:
        from beadsim.lammps_env import lammps_version

        return lammps_version()
    except (ImportError, OSError):
        return "not installed"


def provenance(with_lammps: bool = False) -> dict:
    """A dict of provenance attributes (all strings)."""
    info = {
        "beadsim_version": beadsim.__version__,
        "git_commit": git_commit(),
        "python_version": platform.python_version(),
        "host": platform.node(),
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }
    if with_lammps:
        info["lammps_version"] = lammps_version_or_none()
    return info
