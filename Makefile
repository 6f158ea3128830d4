# Two commands a new user runs: `make demo` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck unit bench clean browser

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

# The panel's end-to-end test drives Debian's headless Chromium (never a downloaded browser).
browser:
	@command -v chromium >/dev/null || { \
	  if [ "$$(id -u)" = 0 ]; then apt-get update -q && apt-get install -y -q chromium chromium-driver; \
	  else sudo apt-get update -q && sudo apt-get install -y -q chromium chromium-driver; fi; }

unit: $(STAMP) browser
	MUJOCO_GL=egl $(BIN)/python -m pytest

test: lint typecheck unit

bench: $(STAMP)
	MUJOCO_GL=egl $(BIN)/biped bench

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .mypy_cache .ruff_cache
