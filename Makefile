# Two commands a new user runs: `make demo` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck unit bench clean system-deps wheel-check fuzz

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

# The panel's end-to-end test drives Debian's headless Chromium (never a downloaded browser);
# the tuner's shared-study test starts a throwaway PostgreSQL server (Debian's).
SYSTEM_PKGS := chromium chromium-driver postgresql
system-deps:
	@{ command -v chromium >/dev/null && ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1; } || { \
	  if [ "$$(id -u)" = 0 ]; then apt-get update -q && apt-get install -y -q $(SYSTEM_PKGS); \
	  else sudo apt-get update -q && sudo apt-get install -y -q $(SYSTEM_PKGS); fi; }

# Three workers on the machine's two cores, a test file per worker at a time: module fixtures
# (a panel, a browser) are built once, and most tests wait on a pty, a socket or a child
# process (two workers kept the load near 1.4: 615 s; three: 488 s, measured back to back).
#
# Bytecode is cached for the run (PYTHONDONTWRITEBYTECODE emptied: some shells set it): the
# suite starts hundreds of Python processes (the servo emulator, `biped` commands, the
# panel's loop), and each compiled the project's sources again (0.1-0.35 CPU-s apiece).
# The files go to the __pycache__ folders git ignores.
unit: $(STAMP) system-deps
	PYTHONDONTWRITEBYTECODE= MUJOCO_GL=egl $(BIN)/python -m pytest -n 3 --dist loadfile --no-loadscope-reorder

# Property tests with fresh random draws and 2000 examples each (make test repeats one draw).
fuzz: $(STAMP)
	BIPED_HYPOTHESIS=fuzz MUJOCO_GL=egl $(BIN)/python -m pytest -n 3 $$(grep -l 'from hypothesis' tests/test_*.py)

# The wheel, installed (not editable) into a fresh venv and run from a directory outside
# the checkout: proves the package ships everything it needs (configs, panel files, the
# sim bus entry point), and that a user can copy a bundled robot file to start from.
# Dependencies come from pip's cache or the registry.
wheel-check: $(STAMP)
	@set -eu; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; start=$$(date +%s); \
	rm -rf build; \
	$(BIN)/python -m pip wheel -q --no-deps . -w "$$tmp/dist" > "$$tmp/build.log" 2>&1 \
	  || { cat "$$tmp/build.log"; echo "wheel-check: building the wheel failed"; exit 1; }; \
	$(PY) -m venv "$$tmp/venv"; \
	"$$tmp/venv/bin/python" -m pip install -q "$$tmp"/dist/biped-*.whl > "$$tmp/install.log" 2>&1 \
	  || { cat "$$tmp/install.log"; echo "wheel-check: installing the wheel failed"; exit 1; }; \
	want="biped $$($(BIN)/python -c 'import tomllib; print(tomllib.load(open("pyproject.toml", "rb"))["project"]["version"])')"; \
	mkdir "$$tmp/run"; cd "$$tmp/run"; \
	got=$$("$$tmp/venv/bin/biped" --version); \
	test "$$got" = "$$want" || { echo "wheel-check: biped --version printed '$$got', expected '$$want'"; exit 1; }; \
	"$$tmp/venv/bin/biped" walk --seconds 0.5 --json > walk.json; \
	"$$tmp/venv/bin/python" -c 'import json, sys; r = json.load(open("walk.json")); sys.exit(0 if r["seconds"] == 0.5 else "wheel-check: walk.json: seconds != 0.5")'; \
	"$$tmp/venv/bin/biped" curves --seconds 1 --robot biped18-feetech --gait crouch --out x.csv; \
	test "$$(wc -l < x.csv)" -gt 1 || { echo "wheel-check: x.csv has no rows"; exit 1; }; \
	"$$tmp/venv/bin/biped" robots copy biped18-feetech mine.toml > /dev/null; \
	"$$tmp/venv/bin/biped" curves --seconds 1 --robot mine.toml --out mine.csv; \
	echo "wheel-check: $$got from the wheel ran walk, curves and robots copy outside the checkout in $$(( $$(date +%s) - start )) s"

test: lint typecheck unit wheel-check

bench: $(STAMP)
	MUJOCO_GL=egl $(BIN)/biped bench

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache .mypy_cache .ruff_cache
