# make run     : create .venv if missing, install arzsumo with its extras, run the default
#                scenario in SUMO and print its result
# make test    : the same set-up, then ruff, the import contracts (lint-imports) and the
#                whole test suite
# make results : the control and penetration studies' tables, read from the committed
#                record store (nothing runs; seconds)
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run results test lint bench clean

$(STAMP): pyproject.toml research/pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test]' -e research
	touch $(STAMP)

RUN_OUT := results/default-etc-seed42-h450s

# the default scenario in SUMO; its result table is the last thing printed
run: $(STAMP)
	@echo "make run: the default scenario in SUMO (about 3 min on 2 cores once installed);"
	@echo "results in $(RUN_OUT)/ (the stored studies' tables: make results)"
	@$(BIN)/arzsumo run --overwrite --out $(RUN_OUT)

# the judged result: the control and penetration studies' tables, reported from the runs
# the committed record store holds (made earlier; nothing runs now, seconds)
RECORDS := research/readings/control_default/records
STUDIES := results/studies

results: $(STAMP)
	@echo "make results: the control and penetration studies, reported from the runs in"
	@echo "$(RECORDS)/ (made earlier; nothing runs now); the headline rows:"
	@t=$$(mktemp) && $(BIN)/arzsumo study control --report \
		--scenario scenarios/default_power_law.toml --seeds 1-20 --records $(RECORDS) \
		--quiet --out $(STUDIES)/control > $$t && mv $$t $(STUDIES)/control/tables.md
	@t=$$(mktemp) && $(BIN)/arzsumo study penetration --report --records $(RECORDS) \
		--quiet --out $(STUDIES)/penetration > $$t && mv $$t $(STUDIES)/penetration/tables.md
	@head -n 1 $(STUDIES)/control/tables.md
	@grep -E '^\| (measure|---|whole-demand time spent, total) ' $(STUDIES)/control/tables.md
	@awk '/section-5 claims/ {f = 1} f {print} f && /^$$/ && n++ {exit}' \
		$(STUDIES)/control/tables.md
	@echo "make results: every table (tables.md) and figure in $(STUDIES)/control/ and $(STUDIES)/penetration/"
	@echo "(what they say: research/readings/current_result.md)"

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks research
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
	$(BIN)/ruff check src tests benchmarks research

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache build src/*.egg-info
