"""Real SLURM: the tiny study through the SLURM profile, checked against sacct and against a workstation run;
a run killed by SLURM is reported failed with SLURM's reason and re-running snakemake redoes only that run.

Needs a running SLURM with accounting (``.ci/slurm/start.sh``, or ``make test-cluster`` which starts and stops
one). Skipped unless ``BEADSIM_SLURM=1`` is set or the controller answers ``scontrol ping``.
"""

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from beadsim.metrics import METRICS

ROOT = Path(__file__).resolve().parents[2]
PROFILES = ROOT / "workflow" / "profiles"
TINY = ROOT / "tests" / "configs" / "tiny.yaml"
TINY_RUNS = {"mode1", "mode3", "P800_Vs4", "P800_Vs6", "P1200_Vs4", "P1200_Vs6"}
# Metrics that measure the machine, not the bead: they differ between any two runs.
TIMING_METRICS = {"wall_time_s", "particle_steps_per_s", "python_time_share"}
SACCT_FIELDS = ("JobID", "State", "ExitCode", "Elapsed", "WorkDir", "Comment")
WORKFLOW_TIMEOUT_S = 1500  # the tiny study takes 1.5-3 min through SLURM on 2 shared cores
POLL_S = 0.5


def _controller_answers() -> bool:
    """True when a SLURM controller answers ``scontrol ping`` (sinfo takes ~10 s to give up on a dead one)."""
    try:
        return subprocess.run(["scontrol", "ping"], capture_output=True, timeout=10).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def _plugin_installed() -> bool:
    try:
        import snakemake_executor_plugin_slurm  # noqa: F401
    except ImportError:
        return False
    return True


pytestmark = [
    pytest.mark.cluster,
    pytest.mark.skipif(os.environ.get("BEADSIM_SLURM") != "1" and not _controller_answers(),
                       reason="no SLURM here: start one (bash .ci/slurm/start.sh) or run make test-cluster"),
    pytest.mark.skipif(os.environ.get("BEADSIM_SLURM") != "1" and not _plugin_installed(),
                       reason="snakemake-executor-plugin-slurm is missing (envs/requirements-cluster.txt)"),
]


def snakemake_cmd(workdir: Path, config: Path, profile: str, *args: str) -> list[str]:
    """The snakemake command line of one study run with the named workflow profile."""
    cmd = [sys.executable, "-m", "snakemake", "--snakefile", str(ROOT / "Snakefile"),
           "--workflow-profile", str(PROFILES / profile), "--configfile", str(config),
           "--directory", str(workdir), *args]
    if profile == "slurm":
        # Poll squeue every few seconds: the profile's 20 s suits a shared cluster, not a test.
        cmd += ["--slurm-init-seconds-before-status-checks", "3"]
    else:
        cmd += ["--cores", "2"]
    return cmd


def run_snakemake(workdir: Path, config: Path, profile: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(snakemake_cmd(workdir, config, profile, *args), capture_output=True, text=True,
                          timeout=WORKFLOW_TIMEOUT_S)


def study_dir(tmp_path_factory, name: str, config: dict) -> tuple[Path, Path]:
    """A fresh working directory holding the study config."""
    work = tmp_path_factory.mktemp(name).resolve()
    path = work / "study.yaml"
    path.write_text(yaml.safe_dump(config))
    return work, path


def sacct_jobs(workdir: Path) -> list[dict]:
    """Jobs (allocations, not steps) that ran in ``workdir``, as dicts of SACCT_FIELDS."""
    out = subprocess.run(["sacct", "-X", "-n", "-P", "-S", "now-1days", "-o", ",".join(SACCT_FIELDS)],
                         capture_output=True, text=True, timeout=60, check=True).stdout
    rows = [dict(zip(SACCT_FIELDS, line.split("|", len(SACCT_FIELDS) - 1))) for line in out.splitlines()]
    return [row for row in rows if row.get("WorkDir") == str(workdir)]


def job_state(workdir: Path, jobid: str) -> str:
    """sacct's State of one job of ``workdir`` ('' while sacct does not know it)."""
    return {row["JobID"]: row["State"] for row in sacct_jobs(workdir)}.get(jobid, "")


def run_id_of(comment: str) -> str:
    """Run id in the plugin's job comment ``rule_simulate_bead_wildcards_<run_id>``; '' for other rules."""
    match = re.fullmatch(r"rule_simulate_bead_wildcards_(?:run_id=)?(\S+)", comment.strip())
    return match.group(1) if match else ""


def wait_for(predicate, timeout_s: float, what: str):
    """Poll ``predicate`` until it returns something truthy; fail after ``timeout_s`` seconds."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(POLL_S)
    pytest.fail(f"timed out after {timeout_s} s waiting for {what}")


def simulate_jobs_final(workdir: Path, n: int) -> list[dict]:
    """The simulate_bead jobs of ``workdir`` once sacct has a final state for ``n`` of them, else []."""
    jobs = [row for row in sacct_jobs(workdir) if run_id_of(row["Comment"])]
    final = [row for row in jobs if row["State"] not in ("PENDING", "RUNNING", "REQUEUED", "SUSPENDED")]
    return final if len(final) >= n else []


@pytest.fixture(scope="module")
def slurm_and_workstation(tmp_path_factory):
    """The tiny study run through the SLURM profile and through the workstation profile."""
    config = yaml.safe_load(TINY.read_text())
    runs = {}
    for profile in ("slurm", "workstation"):
        work, path = study_dir(tmp_path_factory, f"tiny_{profile}", config)
        t0 = time.perf_counter()
        proc = run_snakemake(work, path, profile)
        wall = time.perf_counter() - t0
        assert proc.returncode == 0, proc.stderr[-6000:]
        print(f"tiny study through {profile}: {wall:.1f} s")
        runs[profile] = work
    return runs


def test_sacct_shows_every_run_completed(slurm_and_workstation):
    work = slurm_and_workstation["slurm"]
    jobs = wait_for(lambda: simulate_jobs_final(work, len(TINY_RUNS)), 120, "sacct to record the runs")
    print("\n".join("|".join(row[f] for f in SACCT_FIELDS) for row in jobs))
    assert {run_id_of(row["Comment"]) for row in jobs} == TINY_RUNS
    assert len(jobs) == len(TINY_RUNS)  # one job per run, none resubmitted
    assert all(row["State"] == "COMPLETED" and row["ExitCode"] == "0:0" for row in jobs), jobs
    # The jobs ran the workflow's code: their benchmarks and logs are in the working directory.
    for run_id in TINY_RUNS:
        assert (work / "benchmarks" / "tiny" / "simulate_bead" / f"{run_id}.tsv").stat().st_size > 0
        assert (work / "logs" / "tiny" / "simulate_bead" / f"{run_id}.log").exists()


def test_dataset_equals_the_workstation_run(slurm_and_workstation):
    on_slurm, on_workstation = (xr.load_dataset(slurm_and_workstation[p] / "results" / "tiny" / "dataset.nc")
                                for p in ("slurm", "workstation"))
    on_workstation = on_workstation.sel(case=on_slurm["case"].values)
    assert set(on_slurm["case"].values) == TINY_RUNS
    for name in ("status", "reason", "regime", "model"):
        assert (on_slurm[name].values == on_workstation[name].values).all(), name
    compared = [m for m in METRICS if m not in TIMING_METRICS and m in on_slurm]
    assert "bead_width_mm" in compared and len(compared) > 20
    for name in compared:
        np.testing.assert_allclose(on_slurm[name].values, on_workstation[name].values, rtol=1e-9, atol=0,
                                   equal_nan=True, err_msg=name)


def victim_running(work: Path) -> tuple[str, str] | None:
    """(SLURM job id, run id) of a simulate_bead job of ``work`` that is running now, else None."""
    out = subprocess.run(["squeue", "-h", "-t", "RUNNING", "-o", "%i|%Z|%k"], capture_output=True, text=True,
                         timeout=30).stdout
    for line in out.splitlines():
        jobid, workdir, comment = line.split("|", 2)
        if workdir == str(work) and run_id_of(comment):
            return jobid, run_id_of(comment)
    return None


def test_killed_run_is_reported_and_resumed(tmp_path_factory):
    config = yaml.safe_load(TINY.read_text())
    config["study"] = "kill"
    config["sweep"] = [{"grid": {"beam_power_W": [800, 1200], "substrate_speed_mm_s": [4, 6]}}]
    work, path = study_dir(tmp_path_factory, "kill", config)
    runs = work / "results" / "kill" / "runs"
    log = work / "first.log"
    with log.open("w") as out:
        proc = subprocess.Popen(snakemake_cmd(work, path, "slurm"), stdout=out, stderr=subprocess.STDOUT)
        try:
            jobid, victim = wait_for(lambda: victim_running(work), 600, "a running simulate_bead job")
            subprocess.run(["scancel", jobid], check=True, timeout=30)
            rc = proc.wait(timeout=WORKFLOW_TIMEOUT_S)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(timeout=60)
    text = log.read_text()
    # SLURM's verdict is in sacct and in snakemake's report of the failed job; the other runs went on.
    wait_for(lambda: job_state(work, jobid).startswith("CANCELLED"), 120, f"sacct to show {jobid} cancelled")
    assert rc != 0, text[-4000:]
    assert f"SLURM-job '{jobid}' failed" in text and "CANCELLED" in text, text[-4000:]
    assert not (runs / victim / "result.json").exists()
    survivors = {p.parent.name: p.stat().st_mtime_ns for p in runs.glob("*/result.json")}
    assert set(survivors) == {"P800_Vs4", "P800_Vs6", "P1200_Vs4", "P1200_Vs6"} - {victim}
    # Re-running the same command redoes the killed run only, then the aggregation.
    proc = run_snakemake(work, path, "slurm")
    assert proc.returncode == 0, proc.stderr[-6000:]
    redone = re.findall(r"^rule simulate_bead:\n(?:\s+.*\n)*?\s+wildcards: run_id=(\S+)", proc.stderr, re.M)
    assert redone == [victim], proc.stderr[-6000:]
    kept = {p.parent.name: p.stat().st_mtime_ns for p in runs.glob("*/result.json")
            if p.parent.name != victim}
    assert kept == survivors
    ds = xr.load_dataset(work / "results" / "kill" / "dataset.nc")
    assert ds.sizes["case"] == 4 and (ds["status"].values == "ok").all()


# One small SPH bead (the scene of tests/sph/test_bead.py), run with the profile's execution: sph_tasks 2, mpi srun.
SPH_STUDY = {
    "study": "sph2",
    "description": "cluster test: one small SPH bead on 2 MPI ranks",
    "base": {"model": "sph", "material": "Ti-Gr2", "resolution_mm": 0.4, "sim_time_s": 0.6,
             "domain_margin_mm": 1.5, "domain_depth_mm": 2.4, "beam_power_W": 1000.0,
             "substrate_speed_mm_s": 10.0, "wire_feed_mm_s": 20.0, "scan_diameter_mm": 1.2,
             "beam_spot_radius_mm": 0.2, "wire_length_mm": 1.2, "dump_interval_s": 0.1},
    "sweep": [{"cases": [{"beam_power_W": 1000.0}]}],
}
ENERGY_BALANCE_TOL = 1e-3  # as in tests/sph/test_bead.py


def test_sph_case_runs_on_two_ranks(tmp_path_factory):
    pytest.importorskip("beadsim.sph.mpi_main", reason="beadsim.sph.mpi_main (SPH on MPI ranks) is missing")
    work, path = study_dir(tmp_path_factory, "sph2", SPH_STUDY)
    run = work / "results" / "sph2" / "runs" / "base"
    proc = run_snakemake(work, path, "slurm", str((run / "result.json").relative_to(work)))
    assert proc.returncode == 0, proc.stderr[-6000:]
    result = json.loads((run / "result.json").read_text())
    params = json.loads((run / "params.json").read_text())
    assert result["status"] == "ok", result["reason"]
    assert result["mpi_tasks"] == 2
    m = result["metrics"]
    delivered = params["beam_power_W"] * params["beam_efficiency"] * m["simulated_time_s"]
    assert m["energy_in_J"] == pytest.approx(delivered, rel=1e-6)
    assert abs(m["energy_balance_error"]) < ENERGY_BALANCE_TOL
    # SLURM ran the two ranks as one srun step of two tasks inside the run's allocation.
    (job,) = wait_for(lambda: simulate_jobs_final(work, 1), 120, "sacct to record the SPH job")
    assert job["State"] == "COMPLETED"
    steps = subprocess.run(["sacct", "-j", job["JobID"], "-n", "-P", "-o", "JobID,NTasks,State"],
                           capture_output=True, text=True, timeout=60, check=True).stdout.splitlines()
    assert f"{job['JobID']}.0|2|COMPLETED" in steps, steps
