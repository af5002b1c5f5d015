rule calibrate_parameter:
    input:
        dataset=f"{OUT}/dataset.nc",
        experiments=EXPERIMENTS_FILE,
    output:
        table=report(
            f"{OUT}/calibration/leave_one_out.csv",
            caption="../report/calibration.rst",
            category="Calibration",
            labels={"table": "leave-one-out"},
        ),
        summary=f"{OUT}/calibration/summary.json",
        figure=report(
            f"{OUT}/calibration/curves.png",
            caption="../report/calibration.rst",
            category="Calibration",
            labels={"figure": "response curves"},
        ),
    params:
        parameter=lookup(dpath="analysis/calibration/parameter", within=config, default="beam_efficiency"),
        width_metric=lookup(dpath="analysis/calibration/width_metric", within=config, default="bead_width_mm"),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/calibrate_parameter.log",
    script:
        "../scripts/calibrate_parameter.py"


rule analyze_convergence:
    input:
        f"{OUT}/dataset.nc",
    output:
        table=report(
            f"{OUT}/convergence/richardson.csv",
            caption="../report/convergence.rst",
            category="Convergence",
            labels={"table": "Richardson / GCI"},
        ),
        figure=report(
            f"{OUT}/convergence/convergence.png",
            caption="../report/convergence.rst",
            category="Convergence",
            labels={"figure": "metrics vs resolution"},
        ),
    params:
        parameter=lookup(dpath="analysis/convergence/parameter", within=config, default="resolution_mm"),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/analyze_convergence.log",
    script:
        "../scripts/analyze_convergence.py"


rule analyze_stability:
    input:
        f"{OUT}/dataset.nc",
    output:
        table=report(
            f"{OUT}/stability/classes.csv",
            caption="../report/stability.rst",
            category="Stability",
            labels={"table": "run classes"},
        ),
        figure=report(
            f"{OUT}/stability/stability_map.png",
            caption="../report/stability.rst",
            category="Stability",
            labels={"figure": "stability map"},
        ),
    params:
        options=lookup(dpath="analysis/stability", within=config, default={}),
        axes=config.get("report", {}),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/analyze_stability.log",
    script:
        "../scripts/analyze_stability.py"


rule analyze_speed_accuracy:
    input:
        dataset=f"{OUT}/dataset.nc",
        experiments=EXPERIMENTS_FILE,
    output:
        table=report(
            f"{OUT}/speed_accuracy/table.csv",
            caption="../report/speed_accuracy.rst",
            category="Speed vs accuracy",
            labels={"table": "cost and error per run"},
        ),
        figure=report(
            f"{OUT}/speed_accuracy/pareto.png",
            caption="../report/speed_accuracy.rst",
            category="Speed vs accuracy",
            labels={"figure": "Pareto chart"},
        ),
    params:
        reference=lookup(dpath="analysis/speed_accuracy/reference", within=config, default=""),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/analyze_speed_accuracy.log",
    script:
        "../scripts/analyze_speed_accuracy.py"


rule analyze_uncertainty:
    input:
        experiments=EXPERIMENTS_FILE,
        materials=MATERIALS_FILE,
    output:
        samples=f"{OUT}/uncertainty/samples.csv",
        table=report(
            f"{OUT}/uncertainty/bands.csv",
            caption="../report/uncertainty.rst",
            category="Uncertainty",
            labels={"table": "bands per mode"},
        ),
        figure=report(
            f"{OUT}/uncertainty/bands.png",
            caption="../report/uncertainty.rst",
            category="Uncertainty",
            labels={"figure": "bands against Table 1"},
        ),
    params:
        options=lookup(dpath="analysis/uncertainty", within=config, default={}),
        base=config.get("base", {}),
    threads: 2
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/analyze_uncertainty.log",
    script:
        "../scripts/analyze_uncertainty.py"


rule check_models:
    input:
        f"{OUT}/dataset.nc",
    output:
        report(
            f"{OUT}/model_check/table.csv",
            caption="../report/model_check.rst",
            category="Process maps",
            labels={"table": "SPH checks of the reduced model"},
        ),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/check_models.log",
    script:
        "../scripts/check_models.py"
