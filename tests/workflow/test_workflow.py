"""Real snakemake on a tiny study in a temporary directory: dataset, maps, comparison, report, re-runs, errors."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[2]
SNAKEMAKE = [sys.executable, "-m", "snakemake", "--snakefile", str(ROOT / "Snakefile"),
             "--workflow-profile", str(ROOT / "workflow" / "profiles" / "workstation"), "--cores", "2"]


def snakemake(workdir, config, *args):
    return subprocess.run([*SNAKEMAKE, "--configfile", str(config), "--directory", str(workdir), *args],
                          capture_output=True, text=True, timeout=900)


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    work = tmp_path_factory.mktemp("tiny")
    config = work / "tiny.yaml"
    shutil.copy(ROOT / "tests" / "configs" / "tiny.yaml", config)
    proc = snakemake(work, config)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return work, config


def test_dataset_and_outputs(tiny_run):
    work, _ = tiny_run
    out = work / "results" / "tiny"
    ds = xr.load_dataset(out / "dataset.nc", engine="netcdf4")
    assert ds.sizes["case"] == 6
    assert set(ds["case"].values) == {"mode1", "mode3", "P800_Vs4", "P800_Vs6", "P1200_Vs4", "P1200_Vs6"}
    assert (ds["status"].values == "ok").all()
    assert ds["bead_height_mm"].attrs["units"] == "mm"
    assert ds.attrs["config_digest"] and ds.attrs["git_commit"]
    # Every run has its parameters, result, log and benchmark.
    for run_id in ds["case"].values:
        assert (out / "runs" / run_id / "params.json").exists()
        assert (work / "logs" / "tiny" / "simulate_bead" / f"{run_id}.log").exists()
    assert (ds["job_wall_time_s"].values > 0).all()
    # The comparison found the two measured modes.
    errors = (out / "comparison" / "errors.csv").read_text().splitlines()
    assert len(errors) == 3 and errors[1].startswith("mode1,1,reduced")
    # Uncertainty bands of mode 1 from 4 Latin-hypercube samples: ordered quantiles, the nominal run recorded.
    bands = pd.read_csv(out / "uncertainty" / "bands.csv").set_index("metric")
    width = bands.loc["bead_width_mm"]
    assert width["mode"] == 1 and width["samples_ok"] == 4
    assert width["p05"] <= width["p50"] <= width["p95"] and width["p05"] < width["p95"]
    assert width["nominal"] == pytest.approx(float(ds["bead_width_mm"].sel(case="mode1")), rel=1e-9)
    assert len(pd.read_csv(out / "uncertainty" / "samples.csv")) == 4
    for png in ("maps/process_maps.png", "maps/main_effects.png", "comparison/parity.png",
                "uncertainty/bands.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (out / png).stat().st_size > 20_000


def test_report(tiny_run):
    work, config = tiny_run
    proc = snakemake(work, config, "--report", str(work / "report.html"))
    assert proc.returncode == 0, proc.stderr[-3000:]
    html = (work / "report.html").read_text()
    assert "process_maps.png" in html and "parity.png" in html and "mass_balance.csv" in html


def test_rerun_does_only_what_changed(tiny_run):
    work, config = tiny_run
    proc = snakemake(work, config, "--dry-run")
    assert "Nothing to be done" in proc.stdout + proc.stderr
    changed = yaml.safe_load(config.read_text())
    changed["sweep"][1]["grid"]["beam_power_W"] = [800, 1300]
    config2 = work / "tiny2.yaml"
    config2.write_text(yaml.safe_dump(changed))
    proc = snakemake(work, config2, "--dry-run", "--quiet", "rules")
    text = proc.stdout + proc.stderr
    # Two new runs (P1300_*) plus the aggregation steps; the four unchanged runs are not redone.
    assert _count(text, "simulate_bead") == 2, text


def _count(text, rule):
    for line in text.splitlines():
        parts = line.split()
        if parts and parts[0] == rule:
            return int(parts[1])
    return -1


def test_bad_config_stops_with_the_key_named(tmp_path):
    bad = yaml.safe_load((ROOT / "tests" / "configs" / "tiny.yaml").read_text())
    bad["base"]["wire_angel_deg"] = 45
    config = tmp_path / "bad.yaml"
    config.write_text(yaml.safe_dump(bad))
    proc = snakemake(tmp_path, config, "--dry-run")
    assert proc.returncode != 0
    text = proc.stdout + proc.stderr
    assert "wire_angel_deg" in text and "Additional properties" in text, text


def test_continued_run_waits_for_its_source(tmp_path):
    """continue_from puts the source run before the continued one in the DAG; a source not in the study stops
    the workflow before anything runs, naming the run, the key and the runs allowed."""
    cfg = yaml.safe_load((ROOT / "tests" / "configs" / "tiny_sph.yaml").read_text())
    cfg["base"]["domain"] = "window"
    cfg["sweep"] = [{"cases": [{"name": "a"}, {"name": "b", "sim_time_s": 0.2, "continue_from": "a"}]}]
    config = tmp_path / "cont.yaml"
    config.write_text(yaml.safe_dump(cfg))
    proc = snakemake(tmp_path, config, "--dag")
    assert proc.returncode == 0, proc.stderr[-4000:]
    nodes = dict(re.findall(r'(\d+)\[label = "simulate_bead\\nrun_id: (\w+)"', proc.stdout))
    by_run = {run: node for node, run in nodes.items()}
    assert sorted(by_run) == ["a", "b"], proc.stdout
    assert f"{by_run['a']} -> {by_run['b']}" in proc.stdout and f"{by_run['b']} -> {by_run['a']}" not in proc.stdout
    cfg["sweep"][0]["cases"][1]["continue_from"] = "c"
    config.write_text(yaml.safe_dump(cfg))
    proc = snakemake(tmp_path, config, "--dry-run")
    assert proc.returncode != 0
    assert "run 'b': continue_from: 'c' is not another run of this study; allowed: ['a']" in proc.stdout + proc.stderr


def test_lint_is_clean():
    proc = subprocess.run([sys.executable, "-m", "snakemake", "--snakefile", str(ROOT / "Snakefile"), "--lint"],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_sph_blow_up_is_recorded_and_the_study_completes(tmp_path):
    config = tmp_path / "tiny_sph.yaml"
    shutil.copy(ROOT / "tests" / "configs" / "tiny_sph.yaml", config)
    proc = snakemake(tmp_path, config)
    assert proc.returncode == 0, proc.stderr[-4000:]
    out = tmp_path / "results" / "tiny_sph"
    ds = xr.load_dataset(out / "dataset.nc")
    assert dict(zip(ds["case"].values, ds["status"].values)) == {"dtf1": "ok", "dtf8": "failed"}
    # the watchdog's own reason: dt 8x the limit shows first as a density excursion or as lost particles
    assert re.search(r"(density|particles lost).* at t=", str(ds["reason"].sel(case="dtf8").values))
    assert ds.attrs["lammps_versions"] == "20250722"
    classes = (out / "stability" / "classes.csv").read_text()
    assert "blown_up" in classes and ("stable" in classes or "degraded" in classes)
    for run in ("dtf1", "dtf8"):
        assert (out / "runs" / run / "bead.png").stat().st_size > 10_000
        assert (out / "runs" / run / "section.png").stat().st_size > 5_000  # a section, or a note why none
        assert (out / "runs" / run / "deck.in").exists()
