rule plot_process_maps:
    input:
        dataset=f"{OUT}/dataset.nc",
        experiments=EXPERIMENTS_FILE,
    output:
        maps=report(
            f"{OUT}/maps/process_maps.png",
            caption="../report/process_map.rst",
            category="Process maps",
            labels={"figure": "process maps"},
        ),
        effects=report(
            f"{OUT}/maps/main_effects.png",
            caption="../report/main_effects.rst",
            category="Process maps",
            labels={"figure": "main effects"},
        ),
    params:
        options=config.get("report", {}),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/plot_process_maps.log",
    script:
        "../scripts/plot_process_maps.py"


rule draw_bead:
    input:
        f"{OUT}/runs/{{run_id}}/result.json",
    output:
        temperature=report(
            f"{OUT}/runs/{{run_id}}/bead.png",
            caption="../report/bead.rst",
            category="SPH runs",
            subcategory="{run_id}",
            labels={"run": "{run_id}", "figure": "temperature sections"},
        ),
        section=report(
            f"{OUT}/runs/{{run_id}}/section.png",
            caption="../report/section.rst",
            category="SPH runs",
            subcategory="{run_id}",
            labels={"run": "{run_id}", "figure": "bead cross-section"},
        ),
    params:
        case=get_case,
        materials=MATERIALS_FILE,
        experiments=EXPERIMENTS_FILE,
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/draw_bead/{{run_id}}.log",
    script:
        "../scripts/draw_bead.py"
