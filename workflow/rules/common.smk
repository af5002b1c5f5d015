import re
from pathlib import Path

from snakemake.utils import validate

from beadsim.study import case_params, design, load_experiments

validate(config, schema="../schemas/config.schema.yaml")

STUDY = config["study"]
ROOT = Path(workflow.basedir)


def in_root(path):
    """A config path relative to the workflow root (absolute paths stay)."""
    return str(Path(path) if Path(path).is_absolute() else ROOT / path)


EXPERIMENTS_FILE = in_root(config.get("experiments_file", "config/experiments.csv"))
MATERIALS_FILE = in_root(config.get("materials_file", "config/materials.yaml"))
DESIGN = design(config, load_experiments(EXPERIMENTS_FILE))
RUN_IDS = list(DESIGN.index)
OUT = f"results/{STUDY}"
# Execution settings come from the profile (config: [...]) or --config, never from a study file.
EXECUTION = {"sph_tasks": 1, "mpi": "mpirun", **config.get("execution", {})}


wildcard_constraints:
    run_id="|".join(re.escape(r) for r in RUN_IDS),


def get_case(wildcards):
    """Resolved parameters of one run (a change re-runs it)."""
    return case_params(DESIGN, wildcards.run_id)


def get_continued(wildcards):
    """The result of the run a continue_from run continues (its checkpoint is this run's start)."""
    source = get_case(wildcards).get("continue_from", "")
    return [f"{OUT}/runs/{source}/result.json"] if source else []


def get_tasks(wildcards):
    """MPI ranks of one run: execution.sph_tasks for SPH runs, 1 for the reduced model."""
    return int(EXECUTION["sph_tasks"]) if get_case(wildcards)["model"] == "sph" else 1


def get_mpi(wildcards):
    """The rank launcher, or "" for single-process runs (the SLURM plugin refuses MPI jobs with one task)."""
    return EXECUTION["mpi"] if get_tasks(wildcards) > 1 else ""


def get_results(wildcards=None):
    return expand(f"{OUT}/runs/{{run_id}}/result.json", run_id=RUN_IDS)


def get_benchmarks(wildcards=None):
    return expand(f"benchmarks/{STUDY}/simulate_bead/{{run_id}}.tsv", run_id=RUN_IDS)


def get_final_output():
    analyses = config.get("analysis", {})
    extra = []
    if "calibration" in analyses:
        extra += [f"{OUT}/calibration/leave_one_out.csv", f"{OUT}/calibration/curves.png"]
    if "stability" in analyses:
        extra += [f"{OUT}/stability/classes.csv", f"{OUT}/stability/stability_map.png"]
    if "speed_accuracy" in analyses:
        extra += [f"{OUT}/speed_accuracy/table.csv", f"{OUT}/speed_accuracy/pareto.png"]
    if "uncertainty" in analyses:
        extra += [f"{OUT}/uncertainty/bands.csv", f"{OUT}/uncertainty/bands.png"]
    if "model_check" in analyses:
        extra += [f"{OUT}/model_check/table.csv"]
    if "convergence" in analyses:
        extra += [f"{OUT}/convergence/richardson.csv", f"{OUT}/convergence/convergence.png"]
    sph_runs = [r for r in RUN_IDS if DESIGN.loc[r, "model"] == "sph"]
    extra += expand(f"{OUT}/runs/{{run_id}}/{{figure}}.png", run_id=sph_runs, figure=("bead", "section"))
    return extra + [
        f"{OUT}/dataset.nc",
        f"{OUT}/summary.csv",
        f"{OUT}/maps/process_maps.png",
        f"{OUT}/maps/main_effects.png",
        f"{OUT}/comparison/errors.csv",
        f"{OUT}/comparison/parity.png",
        f"{OUT}/comparison/mass_balance.csv",
    ]
