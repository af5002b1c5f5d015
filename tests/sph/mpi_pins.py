"""``python tests/sph/mpi_pins.py OUTDIR`` on every rank of an MPI job runs :func:`beadsim.sph.mpi_main.main` with
a check of ``contact_freeze`` at every chunk (test_mpi.py): the particles of all ranks gathered, the rule applied
by brute force (every liquid-plate pair within 1.25 dx, held where the pair's mean temperature is below the
melting point) and compared with what the ranks held, each from its own particles and its ghosts. Rank 0 writes
the counts to OUTDIR/pin_check.json: chunks, held, mismatched, and held through a contact owned by another rank
alone (which a rank blind to its ghosts would miss).
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
    from beadsim.sph.scene import TYPE_LIQUID, TYPE_SUBSTRATE

    counts = {"chunks": 0, "held": 0, "mismatched": 0, "across": 0}
    contact_pins = driver.BeadRun._contact_pins

    def checked(self, temp, liquid):
        pinned = contact_pins(self, temp, liquid)
        n = len(temp)
        rank = MPI.COMM_WORLD.rank
        x, types, t, liq, pin, owner = (driver.allgather_rows(self.lmp, a) for a in (
            self._x()[:n], self._types()[:n], temp, liquid, pinned, np.full(n, rank)))
        cold = np.flatnonzero(liq)
        plate = np.flatnonzero(types == TYPE_SUBSTRATE)
        expect = np.zeros(len(t), dtype=bool)
        across = 0
        if len(cold) and len(plate):
            r = np.linalg.norm(x[cold, None, :] - x[None, plate, :], axis=2)
            below = (r < 1.25 * self.num.dx) & (0.5 * (t[cold, None] + t[None, plate]) < self.mat.T_melt)
            expect[cold] = below.any(axis=1)
            same = owner[plate][None, :] == owner[cold][:, None]
            across = int((below.any(axis=1) & ~(below & same).any(axis=1)).sum())
        counts["chunks"] += 1
        counts["held"] += int(pin.sum())
        counts["mismatched"] += int((pin != expect).sum())
        counts["across"] += across
        assert (types[liq] == TYPE_LIQUID).all()
        return pinned

    driver.BeadRun._contact_pins = checked
    mpi_main.main(outdir)
    if MPI.COMM_WORLD.rank == 0:
        (Path(outdir) / "pin_check.json").write_text(json.dumps(counts))


if __name__ == "__main__":
    main(sys.argv[1])
