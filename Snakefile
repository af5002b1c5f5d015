# Electron-beam wire-feed deposition: config sweep -> one simulation per case -> dataset -> maps -> report.
from snakemake.utils import min_version

min_version("9.0")


# The default study, unless a study config is given with --configfile (then that one alone is used).
if not config:

    configfile: f"{workflow.basedir}/config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/aggregate.smk"
include: "workflow/rules/plot.smk"
include: "workflow/rules/analysis.smk"


rule all:
    input:
        get_final_output(),
