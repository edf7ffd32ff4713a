# navlab: two commands — `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# Debian's Chromium drives the viewer's browser tests (Playwright with executable_path; no browser download)
CHROMIUM := /usr/bin/chromium
# Debian's Graphviz lays out `navlab graph` (rqt_graph's layered picture)
DOT := /usr/bin/dot
# Debian's ROS 1 Noetic tools are the peers of the ROS bridge's tests (navlab itself needs no ROS)
ROS_TOOLS := /usr/bin/rosservice
ROS_PACKAGES := python3-rosmaster python3-rospy python3-rostopic python3-rosnode python3-rosbag python3-rosservice \
	python3-rosparam python3-actionlib python3-move-base-msgs python3-nav-msgs python3-sensor-msgs python3-std-srvs \
	python3-tf2-ros tf2-tools rviz xvfb
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
export MUJOCO_GL ?= egl

.PHONY: install demo test lint bench clean clean-cache fuzz

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

$(CHROMIUM):
	$(SUDO) apt-get install -y -q chromium || ($(SUDO) apt-get update -q && $(SUDO) apt-get install -y -q chromium)

$(DOT):
	$(SUDO) apt-get install -y -q graphviz || ($(SUDO) apt-get update -q && $(SUDO) apt-get install -y -q graphviz)

$(ROS_TOOLS):
	$(SUDO) apt-get install -y -q $(ROS_PACKAGES) || ($(SUDO) apt-get update -q && $(SUDO) apt-get install -y -q $(ROS_PACKAGES))

install: $(STAMP) $(CHROMIUM) $(DOT) $(ROS_TOOLS)

demo: $(STAMP)
	$(BIN)/navlab demo

test: $(STAMP) $(CHROMIUM) $(DOT) $(ROS_TOOLS)
	$(BIN)/ruff check src tests examples
	$(BIN)/ruff format --check src tests examples
	$(BIN)/python tools/check_layers.py
	$(BIN)/mypy
	$(BIN)/python -m pytest

# the full fuzz campaign (>= 3,000 malformed inputs over 16 input kinds); a 320-case subset runs in `make test`
fuzz: $(STAMP)
	$(BIN)/python -m tests.fuzz --cases 3200

lint: $(STAMP)
	$(BIN)/ruff check src tests examples
	$(BIN)/ruff format --check src tests examples

bench: $(STAMP)
	$(BIN)/navlab bench all --json

clean: clean-cache
	rm -rf $(VENV) build src/*.egg-info

# Numba keys each cached kernel on its own source file only: a kernel that inlines one from another
# module keeps the old copy after that module changes. Run this after a pull or checkout, before timing.
clean-cache:
	find src -name '*.nbi' -delete -o -name '*.nbc' -delete
