rule aggregate_study:
    input:
        results=get_results(),
        benchmarks=get_benchmarks(),
    output:
        dataset=f"{OUT}/dataset.nc",
        summary=report(
            f"{OUT}/summary.csv",
            caption="../report/summary.rst",
            category="Results",
            labels={"table": "all runs"},
        ),
    params:
        config=config,
        experiments=EXPERIMENTS_FILE,
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/aggregate_study.log",
    script:
        "../scripts/aggregate_study.py"


rule compare_experiments:
    input:
        dataset=f"{OUT}/dataset.nc",
        experiments=EXPERIMENTS_FILE,
    output:
        errors=report(
            f"{OUT}/comparison/errors.csv",
            caption="../report/errors.rst",
            category="Comparison with experiments",
            labels={"table": "errors vs Table 1"},
        ),
        parity=report(
            f"{OUT}/comparison/parity.png",
            caption="../report/parity.rst",
            category="Comparison with experiments",
            labels={"figure": "parity"},
        ),
        mass_balance=report(
            f"{OUT}/comparison/mass_balance.csv",
            caption="../report/mass_balance.rst",
            category="Comparison with experiments",
            labels={"table": "mass balance of measured beads"},
        ),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/compare_experiments.log",
    script:
        "../scripts/compare_experiments.py"
