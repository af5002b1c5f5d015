rule simulate_bead:
    input:
        get_continued,
    output:
        f"{OUT}/runs/{{run_id}}/result.json",
    params:
        case=get_case,
        materials=MATERIALS_FILE,
    conda:
        "../../envs/beadsim.yaml"
    log:
        f"logs/{STUDY}/simulate_bead/{{run_id}}.log",
    benchmark:
        f"benchmarks/{STUDY}/simulate_bead/{{run_id}}.tsv"
    threads: get_tasks
    resources:
        # MPI ranks of the run and their launcher (execution.sph_tasks / execution.mpi, set by the profile).
        tasks=get_tasks,
        mpi=get_mpi,
    script:
        "../scripts/simulate_bead.py"
