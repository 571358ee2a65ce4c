# Two commands do everything on a fresh Debian machine (Python 3.11, root):
#   make demo   set up what is missing, then run the main job on the simulator
#   make test   set up what is missing, then run the whole test suite
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test setup swipl lint clean

setup: swipl $(STAMP)

# Debian packages: SWI-Prolog (the knowledge layer), espeak-ng (the robot's voice, and
# the synthetic caregiver words the speech tests recognise), graphviz (`dot`: the learned tree
# as a picture), libportaudio2 (the microphone, through sounddevice) and chromium (the headless
# browser the monitor's tests drive; nothing downloads a browser). Installed only when missing,
# without recommended packages (swi-prolog-nox recommends a build tool chain relrl does not
# need).
swipl:
	@missing=""; \
	command -v swipl >/dev/null 2>&1 || missing="$$missing swi-prolog-nox"; \
	command -v espeak-ng >/dev/null 2>&1 || missing="$$missing espeak-ng"; \
	command -v dot >/dev/null 2>&1 || missing="$$missing graphviz"; \
	command -v chromium >/dev/null 2>&1 || missing="$$missing chromium"; \
	dpkg -s libportaudio2 >/dev/null 2>&1 || missing="$$missing libportaudio2"; \
	if [ -n "$$missing" ]; then \
	  echo "installing$$missing from Debian's packages"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
	    apt-get install -y -qq --no-install-recommends $$missing; \
	fi

$(STAMP): pyproject.toml Makefile
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[dev,speech,monitor,ray]'
	@touch $(STAMP)

demo: setup
	$(BIN)/relrl demo

test: setup
	$(BIN)/python -m pytest

lint: setup
	$(BIN)/ruff check relrl perception head tests bench

clean:
	rm -rf $(VENV) build *.egg-info
