rule simulate_bead:
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
    threads: 1
    resources:
        # MPI ranks for one SPH run and the launcher (profiles set them: mpirun on a workstation, srun on SLURM).
        tasks=1,
        mpi="mpirun",
    script:
        "../scripts/simulate_bead.py"
