# The two commands of the quick start are `make run` and `make test`; both bootstrap `.venv` first.
SHELL := /bin/bash
VENV := .venv/bin

.PHONY: bootstrap run test test-slow lint bench bench-rtf bench-api

bootstrap:
	@scripts/bootstrap.sh

run: bootstrap
	$(VENV)/laserpick serve

test: bootstrap  ## two workers, a file each at a time: most tests wait on a real-time simulation
	$(VENV)/python -m pytest -q -n 2 --dist loadfile

test-slow: bootstrap
	$(VENV)/python -m pytest -q -m slow

lint: bootstrap
	$(VENV)/ruff check . && $(VENV)/ruff format --check .

bench-rtf: bootstrap  ## real-time factor with the console and cameras (30 s)
	$(VENV)/python bench/realtime_factor.py

bench-api: bootstrap  ## the API under load: 20 watchers and a 50 commands/s controller (60 s)
	$(VENV)/python bench/api_load.py

bench: bootstrap  ## the papers' headline experiments, reports in bench-results/ (docs/bench.md)
	@for p in isolation selection in-situ pick-place; do \
		$(VENV)/laserpick bench --protocol $$p --out bench-results/$$p.json > /dev/null || exit 1; \
	done
	@echo "bench: reports in bench-results/*.md"
