# Everything a fresh machine needs: `make run` (the main job, ending with out/report/index.html)
# and `make test`.
VENV   ?= .venv
# the Python the venv is made from (PYTHON=... chooses; another one: remove $(VENV) first): the
# first python3 on PATH, or the distribution's /usr/bin/python3 when that is the same Python
# version and can make venvs. A distribution's CPython (Debian's, Ubuntu's) is built with PGO and
# LTO and its interpreter linked statically; pyenv's default build is neither: on this project's
# 2-core machines whole catch runs took 10-25 % less CPU on Debian's 3.11 than on pyenv's 3.11.7,
# the logs message-for-message the same. `make bench` prints which interpreter it timed.
SYSTEM_PYTHON := /usr/bin/python3
PYTHON ?= $(shell v() { "$$1" -c 'import sys; print(sys.version_info[:2])' 2>/dev/null; }; \
	if [ -x $(SYSTEM_PYTHON) ] && [ "$$(v python3)" = "$$(v $(SYSTEM_PYTHON))" ] \
	&& $(SYSTEM_PYTHON) -c 'import venv, ensurepip' 2>/dev/null; \
	then echo $(SYSTEM_PYTHON); else echo python3; fi)
PY     := $(VENV)/bin/python
REPLAY := $(VENV)/bin/replay
STAMP  := $(VENV)/.installed
OUT    ?= out

# the default scenarios `make run` runs, writing out/logs, out/figures and out/claims.md; every
# engine's twins (`*_mujoco.yaml`, `*_drake.yaml`: any `<scenario>_<engine>`) are among them, and
# the claims and the report join each with its PyBullet run (analysis/engines.py)
SCENARIOS ?= $(wildcard scenarios/stick_*.yaml scenarios/catch_*.yaml scenarios/grasp_*.yaml)

.PHONY: install run lint test test-pure bench ablations golden-check clean

# (every C source and header of an optional accelerator: a changed kernel is rebuilt by the next
# make; one that does not build is left out and its pure-Python path runs: setup.py)
CSOURCES := $(wildcard replay/*.h replay/*/*.[ch] replay/*/*/*.[ch] plants/*/*.[ch])

$(STAMP): pyproject.toml setup.py $(CSOURCES)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	# the checkout's bytecode, once: where PYTHONDONTWRITEBYTECODE is set (CI, some shells) every
	# command compiled ~290 modules again (~0.25 s a `replay run`); stale files are recompiled
	$(PY) -m compileall -q replay plants analysis
	touch $(STAMP)

install: $(STAMP)

run: $(STAMP)
	@for s in $(SCENARIOS); do $(REPLAY) run $$s -o $(OUT)/logs/$$(basename $$s .yaml).mcap || exit $$?; done
	$(REPLAY) figures $(OUT)/logs/*.mcap -o $(OUT)/figures
	$(REPLAY) claims $(OUT)/logs/*.mcap --markdown $(OUT)/claims.md
	$(REPLAY) report -o $(OUT)/report --logs $(OUT)/logs

# the ablations (sweeps/*.yaml) from scratch, their tables kept under data/ablations/ for the
# report (~3,200 variants, ~1 h of CPU as the sweeps that made them measured: catch_rate 14 min,
# grasp_loops + grasp_components ~25, the stick sweeps 10, catch_optimisation 3); `make run`
# only redraws them
ablations: $(STAMP)
	$(REPLAY) ablate --store --no-logs

# ruff (lint and format: run `ruff format .` before committing) and mypy, configured in pyproject.toml
lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/mypy

# the suite in parallel (pytest-xdist): TEST_WORKERS processes (2: this project's CI machines have
# 2 cores), each test file kept on one worker (--dist loadfile) so a module's fixtures (logs of
# whole runs, a built wheel) are made once, the longest files first (tests/conftest.py's
# LONGEST_FIRST; xdist would order them by test count); `make test TEST_WORKERS=0` runs it in one
# process
TEST_WORKERS ?= 2
test: $(STAMP)
	$(PY) -m pytest -q -n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder

# the pure-Python paths (replay.accel: the accelerators built but not used), what an install
# without a C compiler runs. Only the cameras have an accelerator: their tests (which also hold
# each kernel equal to its Python path) and every golden run, whose logs must not change; the
# rest of the suite never reaches an accelerator, so it is not run twice. (test_wheel_install, in
# `make test`, builds and runs a wheel made with CC=/bin/false as well.)
test-pure: $(STAMP)
	REPLAY_NO_ACCEL=1 $(PY) -m pytest -q tests/replay/sensors
	REPLAY_NO_ACCEL=1 $(REPLAY) golden check

bench: $(STAMP)
	$(PY) -m tools.bench.runs
	$(PY) -m tools.bench.log_costs
	$(PY) -m tools.bench.viewer_load
	$(PY) -m tools.bench.sweep_costs
	$(PY) -m tools.bench.research_sweeps

golden-check: $(STAMP)
	$(REPLAY) golden check

clean:
	rm -rf $(OUT)
