# Two commands do everything on a fresh Debian machine (Python 3.11, root):
#   make demo   set up what the demo needs, then run the main job on the simulator
#   make test   set up what the tests need too, then run the whole test suite
# and, once set up, the loop while editing:
#   make check  lint and the fast tests (those not marked slow)
# Each installs only what is missing; each is quick the second time.
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin

# What each job needs. Debian packages are installed only when missing, without their
# recommended packages (swi-prolog-nox recommends a build tool chain relrl does not need).
#   demo: SWI-Prolog (the knowledge layer) and the runtime with its plots.
#   test: also espeak-ng (the synthetic caregiver words the speech tests recognise), graphviz
#         (`dot`: the learned tree as a picture), libportaudio2 (the microphone, through
#         sounddevice), chromium (the headless browser the monitor's tests drive; nothing
#         downloads a browser) and the extras: speech, monitor, Ray, MCAP and Foxglove, the
#         test tools.
DEMO_EXTRAS := plots
TEST_EXTRAS := dev,speech,monitor,ray,mcap,foxglove
# Stable-Baselines3 (`make sb3`), apart from the tests and without their tools: the demo's
# set-up, torch's CPU build, Stable-Baselines3 (docs/rl-tools.md). torch goes in first, pinned
# to its CPU build by the local version `+cpu` (no CUDA build has it), so Stable-Baselines3
# finds torch present and pulls no CUDA build of several GB. Where pip does not already see
# the CPU wheel, give its index, e.g.
#   make sb3 TORCH="torch==2.13.0+cpu --extra-index-url https://download.pytorch.org/whl/cpu"
TORCH ?= torch==2.13.0+cpu

.PHONY: demo test check sb3 test-sb3 setup setup-demo setup-test debs-demo debs-test lint clean

setup: setup-test
setup-demo: debs-demo $(VENV)/.installed-demo
setup-test: debs-test $(VENV)/.installed-test

# debs-demo / debs-test: `command -v` (or dpkg for a library) decides what is missing.
debs-demo:
	@missing=""; \
	command -v swipl >/dev/null 2>&1 || missing="$$missing swi-prolog-nox"; \
	if [ -n "$$missing" ]; then \
	  echo "installing$$missing from Debian's packages"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
	    apt-get install -y -qq --no-install-recommends $$missing; \
	fi

debs-test:
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

# One virtual environment; each job's stamp records that its extras are in it.
$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip

$(VENV)/.installed-demo: pyproject.toml Makefile | $(BIN)/python
	$(BIN)/pip install -q -e '.[$(DEMO_EXTRAS)]'
	@touch $@

$(VENV)/.installed-test: pyproject.toml Makefile | $(BIN)/python
	$(BIN)/pip install -q -e '.[$(DEMO_EXTRAS),$(TEST_EXTRAS)]'
	@touch $@ $(VENV)/.installed-demo

demo: setup-demo
	$(BIN)/relrl demo

test: setup-test
	$(BIN)/python -m pytest

# Lint, then every test not marked slow (pyproject.toml's `slow` marker; docs/development.md).
check: setup-test
	$(BIN)/ruff check relrl perception head tests bench
	$(BIN)/python -m pytest -m "not slow"

# Stable-Baselines3's PPO and DQN trained on relrl/SharedAttention-v1, each checked to learn.
sb3: setup-demo
	$(BIN)/pip install -q $(TORCH)
	$(BIN)/pip install -q -e '.[$(DEMO_EXTRAS),sb3]'
	$(BIN)/python examples/sb3_shared_attention.py --algo ppo --steps 20000 --check --logdir runs/sb3
	$(BIN)/python examples/sb3_shared_attention.py --algo dqn --steps 20000 --check --logdir runs/sb3

# The tests marked `sb3` (docs/rl-tools.md's Stable-Baselines3 snippet, run as written), which
# need torch and Stable-Baselines3: the tests' set-up, torch's CPU build, then SB3. `make test`
# and `make check` deselect them (tests/conftest.py).
test-sb3: setup-test
	$(BIN)/pip install -q $(TORCH)
	$(BIN)/pip install -q -e '.[$(DEMO_EXTRAS),$(TEST_EXTRAS),sb3]'
	$(BIN)/python -m pytest -m sb3

lint: setup-test
	$(BIN)/ruff check relrl perception head tests bench

clean:
	rm -rf $(VENV) build *.egg-info
