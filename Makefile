# Two commands a new user runs: `make demo` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck unit bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	MUJOCO_GL=egl $(BIN)/biped walk --seconds 10

lint: $(STAMP)
	$(BIN)/ruff check robot sim tests

typecheck: $(STAMP)
	$(BIN)/mypy

unit: $(STAMP)
	MUJOCO_GL=egl $(BIN)/python -m pytest

test: lint typecheck unit

bench: $(STAMP)
	MUJOCO_GL=egl $(BIN)/biped bench

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .mypy_cache .ruff_cache
