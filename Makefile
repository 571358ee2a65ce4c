# Two commands do everything on a fresh Debian machine (Python 3.11, root):
#   make demo   set up what is missing, then run the main job on the simulator
#   make test   set up what is missing, then run the whole test suite
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test setup swipl lint clean

setup: swipl $(STAMP)

swipl:
	@command -v swipl >/dev/null 2>&1 || { \
	  echo "installing swi-prolog-nox from Debian's packages"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq swi-prolog-nox; }

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[dev]'
	@touch $(STAMP)

demo: setup
	$(BIN)/relrl demo

test: setup
	$(BIN)/python -m pytest

lint: setup
	$(BIN)/ruff check relrl perception head tests

clean:
	rm -rf $(VENV) build *.egg-info
