# Two commands do everything on a fresh Debian machine (Python 3.11, root):
#   make demo   set up what is missing, then run the main job on the simulator
#   make test   set up what is missing, then run the whole test suite
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test setup swipl lint clean

setup: swipl $(STAMP)

# Debian packages: SWI-Prolog (the knowledge layer) and espeak-ng (the robot's voice, and
# the synthetic caregiver words the speech tests recognise). Installed only when missing, without
# recommended packages (swi-prolog-nox recommends a build tool chain relrl does not need).
swipl:
	@missing=""; \
	command -v swipl >/dev/null 2>&1 || missing="$$missing swi-prolog-nox"; \
	command -v espeak-ng >/dev/null 2>&1 || missing="$$missing espeak-ng"; \
	if [ -n "$$missing" ]; then \
	  echo "installing$$missing from Debian's packages"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
	    apt-get install -y -qq --no-install-recommends $$missing; \
	fi

$(STAMP): pyproject.toml Makefile
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[dev,speech,ray]'
	@touch $(STAMP)

demo: setup
	$(BIN)/relrl demo

test: setup
	$(BIN)/python -m pytest

lint: setup
	$(BIN)/ruff check relrl perception head tests

clean:
	rm -rf $(VENV) build *.egg-info
