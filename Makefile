# navlab: two commands — `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# Debian's Chromium drives the viewer's browser tests (Playwright with executable_path; no browser download)
CHROMIUM := /usr/bin/chromium
# Debian's Graphviz lays out `navlab graph` (rqt_graph's layered picture)
DOT := /usr/bin/dot
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
export MUJOCO_GL ?= egl

.PHONY: install demo test lint bench clean fuzz

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

install: $(STAMP) $(CHROMIUM) $(DOT)

demo: $(STAMP)
	$(BIN)/navlab demo

test: $(STAMP) $(CHROMIUM) $(DOT)
	$(BIN)/ruff check src tests
	$(BIN)/python tools/check_layers.py
	$(BIN)/mypy
	$(BIN)/python -m pytest

# the full fuzz campaign (>= 2,000 malformed inputs); a 330-case subset runs in `make test`
fuzz: $(STAMP)
	$(BIN)/python -m tests.fuzz --cases 2200

lint: $(STAMP)
	$(BIN)/ruff check src tests

bench: $(STAMP)
	$(BIN)/navlab bench all --json

clean:
	rm -rf $(VENV) build src/*.egg-info
