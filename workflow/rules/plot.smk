rule plot_process_maps:
    input:
        f"{OUT}/dataset.nc",
    output:
        report(
            f"{OUT}/maps/process_maps.png",
            caption="../report/process_map.rst",
            category="Process maps",
            labels={"figure": "process maps"},
        ),
    params:
        options=config.get("report", {}),
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/plot_process_maps.log",
    script:
        "../scripts/plot_process_maps.py"
