"""Run one SPH case on several MPI ranks: ``<launcher> -n N python -m beadsim.sph.mpi_main PARAMS OUTDIR``.

Every rank runs the same driver (LAMMPS splits the particles; the driver reduces whatever it computes between
chunks over ranks). Rank 0 writes ``mpi_result.json`` (status, reason, metrics), which :func:`run_mpi`, called by
the runner in the parent process, turns back into metrics or a :class:`SimulationFailed`. A rank that fails alone
(:class:`~beadsim.errors.RankFailure`: a LAMMPS error on that rank, a Python error in the driver there) writes the
result itself and aborts the job, since the others wait for it and would wait forever.
"""

from __future__ import annotations

import collections
import json
import logging
import os
import shlex
import subprocess
import sys
import threading
from pathlib import Path

from beadsim.errors import RankFailure, SimulationFailed
from beadsim.io import write_json

RESULT = "mpi_result.json"

log = logging.getLogger("beadsim.sph.mpi")


ENTRY = ("-m", "beadsim.sph.mpi_main")


def run_mpi(params: dict, outdir: Path, tasks: int, mpi: str = "mpirun", materials_file=None,
            resume: bool = False, timeout: float | None = None, entry: tuple[str, ...] = ENTRY) -> dict:
    """Launch the case on ``tasks`` ranks with ``mpi`` (e.g. "mpirun", "srun --mpi=pmi2"); return its metrics.

    ``timeout`` (s) ends the ranks (SIGTERM to the launcher, which passes it on) and fails the run. ``entry`` is
    what each rank runs after ``python``, with the output folder appended (tests start a wrapper around
    :func:`main` that breaks one rank).

    Raises
    ------
    SimulationFailed
        With the driver's reason, or with the launcher's exit code and the end of its output when the ranks died
        without writing a result.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    (outdir / RESULT).unlink(missing_ok=True)
    write_json(outdir / "mpi_params.json", {"params": params, "materials_file": str(materials_file or ""),
                                            "resume": resume})
    launcher = shlex.split(mpi)
    if launcher and Path(launcher[0]).name == "mpirun":
        from beadsim.lammps_env import mpirun

        launcher[0] = mpirun()
    cmd = [*launcher, "-n", str(tasks), sys.executable, *entry, str(outdir)]
    # The ranks' output (rank 0's progress lines) goes to mpi.log and to this process's log as it comes, so a
    # multi-rank run shows its progress while it runs.
    tail: collections.deque = collections.deque(maxlen=3)
    with open(outdir / "mpi.log", "w", buffering=1) as fh:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1)
        timed_out = threading.Event()

        def expire():
            timed_out.set()
            _kill(proc)

        timer = threading.Timer(timeout, expire) if timeout else None
        if timer:
            timer.start()
        try:
            for line in proc.stdout:
                fh.write(line)
                if line.strip():
                    tail.append(line.strip())
                    log.info("ranks: %s", line.rstrip())
            code = proc.wait()
        except BaseException:  # interrupted here (Ctrl-C, a test's timeout): the ranks go too
            _kill(proc)
            proc.wait()
            raise
        finally:
            if timer:
                timer.cancel()
    if not (outdir / RESULT).exists():
        why = f"was killed after the timeout of {timeout} s" if timed_out.is_set() else f"exited with code {code}"
        raise SimulationFailed(f"MPI run ({' '.join(cmd[:3])} ...) {why} and no result: {' | '.join(tail)}")
    result = json.loads((outdir / RESULT).read_text())
    metrics = {k: (float("nan") if v is None else v) for k, v in result["metrics"].items()}
    metrics["mpi_ranks"] = result["ranks"]
    if result["status"] != "ok":
        raise SimulationFailed(result["reason"], metrics)
    if code != 0:
        raise SimulationFailed(f"MPI run ({' '.join(cmd[:3])} ...) exited with code {code} after writing a result: "
                               f"{' | '.join(tail)}", metrics)
    return metrics


def _kill(proc: subprocess.Popen, grace: float = 10.0) -> None:
    """End the launcher with SIGTERM, which it passes on to the ranks (mpiexec, srun); SIGKILL after ``grace`` s."""
    proc.terminate()
    try:
        proc.wait(grace)
    except subprocess.TimeoutExpired:
        proc.kill()


def main(outdir: str) -> None:
    from beadsim.lammps_env import preload_mpi

    preload_mpi()
    from mpi4py import MPI

    from beadsim.materials import get_material
    from beadsim.sph.driver import run_case

    out = Path(outdir)
    spec = json.loads((out / "mpi_params.json").read_text())
    params = spec["params"]
    material = get_material(params["material"], spec["materials_file"] or None)
    comm = MPI.COMM_WORLD
    # progress (INFO) from rank 0 only; the other ranks would repeat its lines
    logging.basicConfig(level=logging.INFO if comm.rank == 0 else logging.ERROR, stream=sys.stderr,
                        format="%(asctime)s %(name)s %(levelname)s %(message)s")
    status, reason, metrics = "ok", "", {}
    try:
        metrics = run_case(params, out, material=material, resume=spec["resume"])
    except SimulationFailed as exc:
        if isinstance(exc, RankFailure):
            _abort(comm, out, exc.reason, exc.metrics, exc.__cause__)
        status, reason, metrics = "failed", exc.reason, exc.metrics
    except BaseException as exc:  # any other error, perhaps on this rank alone (in rank 0's file writing, say)
        _abort(comm, out, f"{type(exc).__name__} on rank {comm.rank} of {comm.size}: {exc}", {}, exc)
    if comm.rank == 0:
        write_json(out / RESULT, {"status": status, "reason": reason, "metrics": metrics, "ranks": comm.size})


def _abort(comm, out: Path, reason: str, metrics: dict, cause: BaseException | None) -> None:
    """A failure on this rank that the others may never learn of (they wait for it inside LAMMPS or in a
    collective, and would wait forever): write the result from here (rank 0 may be one of the waiting), then
    end the whole job."""
    log.error("rank %d: %s", comm.rank, reason, exc_info=cause)
    write_json(out / RESULT, {"status": "failed", "reason": reason, "metrics": metrics, "ranks": comm.size})
    sys.stderr.flush()
    comm.Abort(1)
    # MPI_Abort can return before the launcher ends this process (seen: rank 0 went on and wrote "ok" over the
    # failure); nothing may run after it
    os._exit(1)


if __name__ == "__main__":
    main(sys.argv[1])
