# cotm-bertini: every target installs what it needs (idempotent), then runs.
PY      ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.installed
CLI     := $(BIN)/cotm-bertini

.PHONY: install case1 case2 case3 test lint format clean-runs

$(STAMP): pyproject.toml
	@$(PY) -c 'import venv, ensurepip' 2>/dev/null || { \
	  echo "installing Debian python3-venv"; \
	  apt-get update -qq && apt-get install -y -qq python3-venv; }
	@test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/pip install -q --disable-pip-version-check -e '.[dev]'
	@touch $@

install: $(STAMP)

case1 case2 case3: $(STAMP)
	$(CLI) solve $@

test: $(STAMP)
	$(BIN)/pytest -q

lint: $(STAMP)
	$(BIN)/ruff check cotm_bertini tests
	$(BIN)/ruff format --check cotm_bertini tests

format: $(STAMP)
	$(BIN)/ruff format cotm_bertini tests
	$(BIN)/ruff check --fix cotm_bertini tests

clean-runs:
	find runs -mindepth 1 -maxdepth 1 ! -name README.md -exec rm -rf {} +
