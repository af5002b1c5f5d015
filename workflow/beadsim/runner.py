"""Run one case with the model it names and record the outcome, whatever happens.

Writes into the run folder:
- ``params.json``: the resolved parameters;
- ``result.json``: ``status`` (``ok`` or ``failed``), ``reason``, the metrics, the provenance.
A failed run is a result: the sweep goes on and aggregation reports it with its reason.
"""

from __future__ import annotations

import json
import logging
import shutil
import time
import traceback
from pathlib import Path

import numpy as np

from beadsim.errors import SimulationFailed
from beadsim.io import atomic_path, write_json
from beadsim.materials import get_material
from beadsim.provenance import provenance

log = logging.getLogger("beadsim.runner")


def run_model(params: dict, outdir: Path, materials_file=None, tasks: int = 1, mpi: str = "mpirun",
              run_id: str = "") -> dict:
    """Dispatch to the model named by ``params['model']``; return its metrics.

    SPH runs with ``tasks > 1`` are launched as ``<mpi> -n <tasks> python -m beadsim.sph.mpi_main`` (``mpi``
    may hold options, e.g. "srun --mpi=pmi2"); the reduced model always runs in this process.
    """
    material = get_material(params["material"], materials_file)
    resume = params["model"] == "sph" and _can_resume(params, outdir)
    write_json(outdir / "params.json", {"run_id": run_id, **params})
    if params["model"] == "sph" and params.get("continue_from") and not resume:
        seed_continuation(params["continue_from"], outdir)
        resume = True
    if params["model"] == "reduced":
        from beadsim.reduced import run_reduced

        return run_reduced(params, material)
    if params["model"] == "sph":
        if resume:
            log.info("resuming from the checkpoint in %s", outdir / "restart")
        if tasks > 1:
            from beadsim.sph.mpi_main import run_mpi

            return run_mpi(params, outdir, tasks=tasks, mpi=mpi, materials_file=materials_file, resume=resume)
        from beadsim.sph.driver import run_case as run_sph

        return run_sph(params, outdir, material=material, resume=resume)
    raise ValueError(f"model {params['model']!r} is not one of reduced, sph")


def _can_resume(params: dict, outdir: Path) -> bool:
    """A killed SPH run left a checkpoint made with the same parameters: continue it instead of starting over.
    A finished run's last checkpoint is not resumed: a forced rerun (snakemake deletes result.json first) is
    meant to run again, with the code as it is now."""
    old, state = outdir / "params.json", outdir / "restart" / "state.npz"
    if not state.exists() or not old.exists():
        return False
    previous = json.loads(old.read_text())
    previous.pop("run_id", None)
    if previous != json.loads(json.dumps(params)):
        return False
    with np.load(state) as data:
        finished = json.loads(str(data["state"])).get("finished", False)
    if finished:
        log.info("the checkpoint in %s is a finished run's: starting over", outdir / "restart")
    return not finished


#: files of a run folder that a continuation does not take from its source (besides the pictures, *.png)
_NOT_CONTINUED = ("params.json", "result.json", "continued_from.json")


def seed_continuation(source_id: str, outdir: Path) -> None:
    """Start a ``continue_from`` run from the finished run ``source_id`` beside ``outdir``: take its checkpoint
    (marked unfinished, so that it is resumed), dumps, deck, logs and time series, and write
    ``continued_from.json`` (the source, where it ended, and the provenance of the code that ran it).

    Raises
    ------
    SimulationFailed
        The source has no result, failed, or left no checkpoint.
    """
    src = outdir.parent / source_id
    result = src / "result.json"
    if not result.exists():
        raise SimulationFailed(f"continue_from {source_id!r}: {result} does not exist (run the source first)")
    record = json.loads(result.read_text())
    if record["status"] != "ok":
        raise SimulationFailed(f"continue_from {source_id!r}: the source run failed ({record['reason']}): "
                               "nothing sound to continue")
    state_file = src / "restart" / "state.npz"
    if not state_file.exists():
        raise SimulationFailed(f"continue_from {source_id!r}: the source left no checkpoint ({state_file})")
    for sub in ("dumps", "restart"):  # what an earlier attempt left here is not this run's history
        shutil.rmtree(outdir / sub, ignore_errors=True)
    for item in sorted(src.iterdir()):
        if item.name in _NOT_CONTINUED or item.suffix == ".png":
            continue
        if item.is_dir():
            shutil.copytree(item, outdir / item.name)
        else:
            shutil.copy2(item, outdir / item.name)
    with np.load(outdir / "restart" / "state.npz") as data:
        arrays = {k: data[k] for k in data.files}
    state = json.loads(str(arrays["state"]))
    write_json(outdir / "continued_from.json", {
        "run_id": source_id, "t_s": state["t"], "step": state["step"], "source_elapsed_s": record["elapsed_s"],
        "provenance": record["provenance"]})
    # last: until the checkpoint reads unfinished, an interrupted seeding is seeded again, not resumed
    state["finished"] = False
    arrays["state"] = json.dumps(state)
    with atomic_path(outdir / "restart" / "state.npz") as tmp:
        np.savez(tmp, **arrays)
    log.info("continuing %s from t = %.4g s (step %d)", source_id, state["t"], state["step"])


def run_case(params: dict, outdir: str | Path, run_id: str = "", materials_file=None, tasks: int = 1,
             mpi: str = "mpirun") -> dict:
    """Run one case and write ``params.json`` and ``result.json`` (atomically) into ``outdir``.

    Returns
    -------
    dict
        The record written to ``result.json``.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    status, reason, metrics = "ok", "", {}
    try:
        metrics = run_model(params, outdir, materials_file, tasks=tasks, mpi=mpi, run_id=run_id)
    except SimulationFailed as exc:
        status, reason, metrics = "failed", exc.reason, exc.metrics
        log.error("run %s failed: %s", run_id, exc.reason)
    except Exception as exc:  # a failed run must not stop the sweep; the traceback goes to the log
        status, reason = "failed", f"error: {type(exc).__name__}: {exc}"
        log.error("run %s raised:\n%s", run_id, traceback.format_exc())
    record = {
        "run_id": run_id,
        "status": status,
        "reason": reason,
        "model": params["model"],
        "mpi_tasks": tasks if params["model"] == "sph" else 1,
        "metrics": metrics,
        "elapsed_s": time.perf_counter() - t0,
        "provenance": provenance(with_lammps=params["model"] == "sph"),
    }
    seeded = outdir / "continued_from.json"
    if params.get("continue_from") and seeded.exists():
        source = json.loads(seeded.read_text())
        if source["run_id"] == params["continue_from"]:
            record["continued_from"] = source
    write_json(outdir / "result.json", record)
    log.info("run %s: %s %s (%.2f s)", run_id, status, reason, record["elapsed_s"])
    return record
