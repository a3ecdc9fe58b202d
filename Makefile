# The two commands of the README: `make demo` and `make test` (each does all set-up).
.PHONY: setup demo test lint typecheck pytest bench clean

VENV := .venv/bin

setup:
	bash tools/setup.sh

demo: setup
	mkdir -p out
	$(VENV)/virja render virja/demo/blues.mid --out out/demo.mp4

lint: setup
	$(VENV)/ruff check virja tests tools
	$(VENV)/ruff format --check virja tests tools

typecheck: setup
	$(VENV)/mypy

pytest: setup
	$(VENV)/python -m pytest -q

test: lint typecheck pytest

bench: setup
	$(VENV)/virja bench

clean:
	rm -rf out .pytest_cache .mypy_cache .ruff_cache
