"""``python tests/sph/mpi_ceiling.py OUTDIR`` on every rank of an MPI job runs :func:`beadsim.sph.mpi_main.main` with
a check of the smoothed loose-melt ceiling at every chunk (test_mpi.py). Each rank caps the density of the melt it
owns from its own and its ghost particles (the deck extends the ghosts' reach by the smoothing radius); the check
gathers every rank's particles before the cap, applies the cap to the gathered set in another order (reversed ids),
where nothing lies beyond any rank's reach, and compares the densities the ranks wrote, by particle id. Rank 0
writes the counts to OUTDIR/ceiling_check.json: chunks, melt particles checked, particles whose density the cap
lowered, the largest density change (kg/m^3), the largest difference between the ranks' and the fresh densities
(kg/m^3) and how many of the melt particles differ by more than 1e-9 of rho0 (flipped).
"""

import json
import sys
from pathlib import Path

import numpy as np


def main(outdir: str) -> None:
    from beadsim.lammps_env import preload_mpi

    preload_mpi()
    from mpi4py import MPI

    from beadsim.sph import driver, mpi_main
    from beadsim.sph.scene import TYPE_LIQUID

    comm = MPI.COMM_WORLD
    counts = {"chunks": 0, "melt": 0, "capped": 0, "change_max": 0.0, "diff_max": 0.0, "flipped": 0}
    ceiling = driver.BeadRun._loose_melt_ceiling

    def checked(self):
        n = self._nlocal()
        # gathered before the cap (which lowers rho in place: a copy, as one rank gathers its own array) and after
        # it; the cap moves no particle, so both gathers list the same particles in the same order
        ids, x, rho, types = (driver.allgather_rows(self.lmp, a)
                              for a in (self._ids(), self._x()[:n], self._rho()[:n].copy(), self._types()[:n]))
        ceiling(self)
        rho_after = driver.allgather_rows(self.lmp, self._rho()[:n])
        melt = types == TYPE_LIQUID
        if not melt.any():
            return
        order = np.argsort(-ids)  # compute again with the gathered particles in reversed id order
        capped = rho[order]
        p = self.p
        driver.relax_loose_density(capped, x[order], np.flatnonzero(melt[order]), self.num.dx, self.mat.rho,
                                   self.num.tait_rho0, self.chunk, p["loose_melt_d3"], p["loose_melt_smoothing"])
        fresh = np.empty_like(rho)
        fresh[order] = capped
        diff = np.abs(rho_after[melt] - fresh[melt])
        counts["chunks"] += 1
        counts["melt"] += int(melt.sum())
        counts["capped"] += int((fresh[melt] < rho[melt]).sum())
        counts["change_max"] = max(counts["change_max"], float((rho[melt] - fresh[melt]).max()))
        counts["diff_max"] = max(counts["diff_max"], float(diff.max()))
        counts["flipped"] += int((diff > 1e-9 * self.mat.rho).sum())

    driver.BeadRun._loose_melt_ceiling = checked
    mpi_main.main(outdir)
    if comm.rank == 0:
        (Path(outdir) / "ceiling_check.json").write_text(json.dumps(counts))


if __name__ == "__main__":
    main(sys.argv[1])
