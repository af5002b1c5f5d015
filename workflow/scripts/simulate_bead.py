"""Run one case (any model) and write params.json + result.json into its run folder."""

from pathlib import Path

from beadsim.logs import configure_logging
from beadsim.runner import run_case

configure_logging(snakemake.log[0])
out = Path(snakemake.output[0])
run_case(snakemake.params.case, out.parent, run_id=snakemake.wildcards.run_id,
         materials_file=snakemake.params.materials, tasks=int(snakemake.resources.tasks),
         mpi=str(snakemake.resources.mpi))
