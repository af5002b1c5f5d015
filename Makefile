# Two commands do everything on a fresh machine (Python 3.11 + pip + gcc):
#   make run    # environment + the default study + results/report.html
#   make test   # environment + the test suite
# Other studies: make run STUDY=<name>   (config/studies/<name>.yaml -> results/<name>/report.html)

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
CORES ?= all
STUDY ?=
ifeq ($(STUDY),)
CONFIG ?= config/config.yaml
REPORT ?= results/report.html
else
CONFIG ?= config/studies/$(STUDY).yaml
REPORT ?= results/$(STUDY)/report.html
endif
PROFILE := --workflow-profile workflow/profiles/workstation
SNAKEMAKE := $(BIN)/snakemake --configfile $(CONFIG) $(PROFILE) --cores $(CORES)

.PHONY: env run report test test-cluster lint schema bench clean

env: $(STAMP)

$(STAMP): envs/requirements.txt envs/constraints.txt pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -r envs/requirements.txt -c envs/constraints.txt
	$(BIN)/pip install --quiet --no-deps -e .
	touch $(STAMP)

run: env
	$(SNAKEMAKE)
	$(MAKE) report

report: env
	$(SNAKEMAKE) --report $(REPORT)
	@echo "report: $(REPORT)"

test: env
	$(BIN)/python -m pytest -q -m "not cluster" $(PYTEST_ARGS)

# Starts a single-node SLURM on this machine (root; installs slurm-wlm, munge, slurmdbd, mariadb once), runs the
# tiny study through workflow/profiles/slurm (tests/cluster), stops SLURM.
test-cluster: env
	$(BIN)/pip install --quiet -r envs/requirements-cluster.txt -c envs/constraints.txt
	bash .ci/slurm/start.sh && BEADSIM_SLURM=1 $(BIN)/python -m pytest -q tests/cluster $(PYTEST_ARGS); \
	rc=$$?; bash .ci/slurm/stop.sh; exit $$rc

# Speed benchmark of the SPH model (beadsim/bench.py): throughput on 1 and 2 ranks, the Table 4 modes with all
# speed levers, the whole plate (estimated from its per-step cost), window vs whole plate at a coarse dx.
# Options: make bench BENCH_ARGS="--dx 0.3 --modes 1"   (python -m beadsim.bench --help)
bench: env
	$(BIN)/python -m beadsim.bench $(BENCH_ARGS)

lint: env
	$(BIN)/snakemake --lint --configfile $(CONFIG)

schema: env
	$(BIN)/python -m beadsim.schema

clean:
	rm -rf .snakemake logs benchmarks results/*/ results/report.html
