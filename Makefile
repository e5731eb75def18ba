# The two commands of the README: `make run` and `make test`. Each installs what it needs the
# first time (a venv with every package pinned by constraints.txt, the CMake path fix of
# ROS_WHEELS.md, a colcon build) and skips what is already done.
SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON ?= python3
VENV := .venv
WS := tools/ws
DEPS_STAMP := $(VENV)/.deps-stamp
BUILD_STAMP := install/.build-stamp
SOURCES := $(shell find src vendor -type f -not -path '*/__pycache__/*' -not -name '*.pyc' 2>/dev/null)
# vendor/ packages (COLCON_IGNORE'd) built only where the environment lacks them: vendor/README.md
VENDORED := $(if $(wildcard $(VENV)/share/tf2_msgs/package.xml /opt/ros/jazzy/share/tf2_msgs/package.xml),,vendor/tf2_msgs)
PYTEST_ARGS ?=
# The paper's test case (docs/paper-test-case.md). `make run` decides its first part, PTH0, on
# three iterations per bin, per n and three feeder runs (the fewest that decide both options:
# docs/decisions.md); RUN_ARGS="--iterations 3 $(TEST_CASE)" runs all three parts so,
# RUN_ARGS="--adaptive $(TEST_CASE)" until each decision is settled, RUN_ARGS="" the built-in
# small file.
TEST_CASE := $(addprefix src/experiment_manager/config/test_case/,pth0.yaml pth1.yaml pth2.yaml)
DEFAULT_RUN_ARGS := --iterations 3 src/experiment_manager/config/test_case/pth0.yaml
RUN_ARGS ?= $(DEFAULT_RUN_ARGS)

.PHONY: help run test test-loaded lint bench deps build lock clean

help:
	@echo "make run    - the paper's PTH0 decided through the graph (RUN_ARGS=\"file.yaml\")"
	@echo 'make test   - lint and run every test (installs and builds on first use)'
	@echo 'make test-loaded - make test three times with every CPU kept busy by other loops'
	@echo 'make bench  - world and validity timings, each against a baseline of the same run'
	@echo 'make clean  - remove build/, install/, log/ (keeps the venv)'

$(DEPS_STAMP): requirements.txt constraints.txt tools/fix_cmake_paths.py
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --disable-pip-version-check pip==26.3
	$(VENV)/bin/python -m pip install --quiet -r requirements.txt -c constraints.txt
	$(VENV)/bin/python tools/fix_cmake_paths.py
	touch $@

deps: $(DEPS_STAMP)

# The Python packages are installed afresh: colcon copies modules into install/ and never
# removes one that was moved or deleted in src/, which would then still import.
PY_PACKAGES := $(notdir $(patsubst %/setup.py,%,$(wildcard src/*/setup.py)))

$(BUILD_STAMP): $(DEPS_STAMP) $(SOURCES) colcon.meta
	rm -rf $(addprefix install/,$(PY_PACKAGES)) $(addprefix build/,$(PY_PACKAGES))
	$(WS) colcon build --base-paths . $(VENDORED) \
	    --event-handlers console_cohesion- summary+ status- \
	    --cmake-args -DBUILD_TESTING=OFF -Wno-dev
	touch $@

build: $(BUILD_STAMP)

run: $(BUILD_STAMP)
	$(WS) install/experiment_manager/lib/experiment_manager/run $(RUN_ARGS)
	@if [ "$(RUN_ARGS)" = "$(DEFAULT_RUN_ARGS)" ]; then \
	  echo "the test case's other parts: make run RUN_ARGS=\"--iterations 3 $(word 2,$(TEST_CASE))\" (PTH1),"; \
	  echo "  $(word 3,$(TEST_CASE)) (PTH2); all three until settled: make run RUN_ARGS=\"--adaptive $(TEST_CASE)\""; \
	fi

lint: $(DEPS_STAMP)
	$(WS) ruff check src tests bench studies tools

test: $(BUILD_STAMP) lint
	$(WS) python -m pytest $(PYTEST_ARGS)

test-loaded: $(BUILD_STAMP)
	$(PYTHON) tools/loaded.py --rounds 3 -- $(MAKE) test

bench: $(BUILD_STAMP)
	$(WS) python -m bench.world.bench_world
	$(WS) python -m bench.validity.bench_validity

lock: $(DEPS_STAMP)
	$(VENV)/bin/python -m pip freeze --exclude-editable | sort > constraints.txt.new
	@echo 'review constraints.txt.new, then move it over constraints.txt'

clean:
	rm -rf build install log
