"""``python tests/sph/mpi_hf.py OUTDIR`` on every rank of an MPI job runs :func:`beadsim.sph.mpi_main.main` with
a check of ``surface_force: height_function`` at every chunk (test_mpi.py). The forces are computed from the
gathered positions and each rank writes those of the particles it owns; so at the start of each chunk the forces
the ranks wrote, gathered by particle id, are compared with the forces computed afresh from the gathered
particles in another order (reversed ids), and at its end, after particles have changed rank, with what was
written at its start (the force is held over the chunk and must travel with its particle). Rank 0 writes the
counts to OUTDIR/hf_check.json: chunks, particles forced, the largest difference of each kind (N), the largest
force (N), how many forced particles changed rank during a chunk, and how many of the gathered particles no
rank owned (missing).
"""

import json
import sys
from pathlib import Path

import numpy as np


def main(outdir: str) -> None:
    from beadsim.lammps_env import preload_mpi

    preload_mpi()
    from mpi4py import MPI

    from beadsim.sph import driver, heightfn, mpi_main

    comm = MPI.COMM_WORLD
    counts = {"chunks": 0, "forced": 0, "written_diff": 0.0, "carried_diff": 0.0, "f_max": 0.0, "moved": 0,
              "missing": 0}
    surface_forces, heightfn_forces = driver.BeadRun._surface_forces, heightfn.surface_forces
    calls: list = []
    held: dict = {}  # ids, forces and owning ranks as written at the chunk's start, in id order

    def recorded(*args, **kwargs):  # the driver's call: keep its arguments (the grid) for the fresh computation
        calls.append((args, kwargs))
        return heightfn_forces(*args, **kwargs)

    def written(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = self._nlocal()
        f = np.column_stack([self.lmp.numpy.extract_atom(f"d_hf{c}")[:n] for c in "xyz"])
        ids, f, rank = (driver.allgather_rows(self.lmp, a) for a in (self._ids(), f, np.full(n, comm.rank)))
        return ids, f, rank

    def checked(self):
        if held:  # the chunk that just ended: each particle's force as written at its start, wherever it went
            ids, f, rank = written(self)
            keep = np.isin(ids, held["ids"])
            where = np.searchsorted(held["ids"], ids[keep])
            counts["carried_diff"] = max(counts["carried_diff"], float(np.abs(f[keep] - held["f"][where]).max()))
            forced = np.abs(held["f"][where]).max(axis=1) > 0
            counts["moved"] += int((forced & (rank[keep] != held["rank"][where])).sum())
        calls.clear()
        surface_forces(self)
        (x, movable, grid, *rest), kwargs = calls[-1]
        ids, f, rank = written(self)
        sort = np.argsort(ids)
        ids_all = ids[sort]  # the driver's gathered particles, in id order
        order = np.argsort(-ids_all)  # compute again in the reverse order
        kwargs = dict(kwargs, mapped=kwargs["mapped"][order])
        f_fresh = np.empty_like(x)
        f_fresh[order] = heightfn_forces(x[order], movable[order], grid, *rest, **kwargs)[0]
        where = np.searchsorted(ids_all, ids)
        counts["chunks"] += 1
        counts["forced"] += int((np.abs(f).max(axis=1) > 0).sum())
        counts["f_max"] = max(counts["f_max"], float(np.abs(f_fresh).max()))
        counts["written_diff"] = max(counts["written_diff"], float(np.abs(f - f_fresh[where]).max()))
        counts["missing"] += len(x) - len(ids)
        held.update(ids=ids_all, f=f[sort], rank=rank[sort])

    driver.heightfn.surface_forces = recorded
    driver.BeadRun._surface_forces = checked
    mpi_main.main(outdir)
    if comm.rank == 0:
        (Path(outdir) / "hf_check.json").write_text(json.dumps(counts))


if __name__ == "__main__":
    main(sys.argv[1])
