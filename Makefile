# make run  : create .venv if missing, install arzsumo with its extras, run the default job,
#             then print the control and penetration studies' results from their record store
# make test : the same set-up, then ruff, the import contracts (lint-imports) and the whole
#             test suite
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test lint bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test]'
	touch $(STAMP)

# the default run, then the judged result: the control and penetration studies' tables
# from the committed record store (nothing runs; seconds)
RECORDS := docs/readings/control_default/records

run: $(STAMP)
	$(BIN)/arzsumo run --overwrite
	$(BIN)/arzsumo study control --report --seeds 1-20 --records $(RECORDS) --quiet
	$(BIN)/arzsumo study penetration --report --records $(RECORDS) --quiet

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/lint-imports
	$(BIN)/python -m pytest -q -n 2

# make bench: the quick benchmarks (numerics only, no SUMO; 1-2 min), each printing ratios;
# the SUMO ones (bench_cosim, bench_sensing, bench_sumo_measurement, bench_network_measures,
# bench_estimation_cost, bench_evaluate) and bench_sweep take longer: run them by hand
bench: $(STAMP)
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/bench_etc.py
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/bench_kernels.py
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/bench_compensation_cost.py --checks 500
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/bench_delay_predictor.py --delays 0 6 14
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/bench_estimate.py --periods 50
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/bench_identify.py --quick
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/bench_twin.py --quick

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache build src/*.egg-info
