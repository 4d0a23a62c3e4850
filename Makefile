# cotm-bertini: every target installs what it needs (idempotent), then runs.
PY      ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.installed
CLI     := $(BIN)/cotm-bertini

.PHONY: install phcpack browser case1 case2 case3 test stress sweep map explore bench verify paper lint format clean-runs

$(STAMP): pyproject.toml
	@$(PY) -c 'import venv, ensurepip' 2>/dev/null || { \
	  echo "installing Debian python3-venv"; \
	  apt-get update -qq && apt-get install -y -qq python3-venv; }
	@test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/pip install -q --disable-pip-version-check -e '.[dev]'
	@touch $@

install: $(STAMP)

# PHCpack (Debian) is a peer solver for cross-checks and benchmarks only.
phcpack:
	@command -v phc >/dev/null || { \
	  echo "installing Debian phcpack"; \
	  apt-get update -qq && apt-get install -y -qq phcpack >/dev/null; }

# Debian's Chromium and its driver: the explorer pages' browser tests (tests/test_explore.py).
browser:
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null || { \
	  echo "installing Debian chromium and chromium-driver"; \
	  apt-get update -qq && apt-get install -y -qq chromium chromium-driver >/dev/null; }

# The cli engine keeps Bertini's own output files in the run folder for inspection;
# `cotm-bertini solve` without --engine uses the faster in-process parameter homotopy.
case1 case2 case3: $(STAMP)
	$(CLI) solve $@ --engine cli

# Two pytest-xdist workers (the CI machine's 2 cores); the costly framework examples share one
# worker (xdist_group) and every worker one fresh cache, so each generic set is solved once.
test: $(STAMP) phcpack browser
	$(BIN)/pytest -q -m "not slow" -n 2 --dist loadgroup

verify: $(STAMP) phcpack
	$(CLI) verify case1 && $(CLI) verify case2 && $(CLI) verify case3

paper: $(STAMP)
	$(CLI) paper --out runs/paper

# The paper's sweep (Figs 5-6): L01 from 0 to 12 m at 241 points, L02 = 0, Table 1.
sweep: $(STAMP)
	$(CLI) sweep --param L01 --from 0 --to 12 --points 241 --out runs

# The design map of the paper geometry: stable-count regions (101 x 101 solves) and fold curves.
map: $(STAMP)
	$(CLI) map --param L01 --from 0 --to 14 --param2 L02 --from2 0 --to2 14 --points 101

# The same map with its explorer page: runs/map/latest/explore.html, opened from disk.
explore: $(STAMP)
	$(CLI) map --param L01 --from 0 --to 14 --param2 L02 --from2 0 --to2 14 --points 101 --html

# The full stress set (200 random geometries, 20 seeds); `make test` runs a fast subset.
stress: $(STAMP) phcpack
	COTM_STRESS=full $(BIN)/pytest -q tests/stress tests/test_fold_curves.py \
	  tests/test_frameworks.py::test_cotm_framework_random_geometries \
	  tests/test_certify_frameworks.py \
	  tests/test_barriers_frameworks.py::test_spatial_top_barrier_against_the_closed_form \
	  tests/test_scaleout.py::test_double_pendulum_generic_set_split_equals_bertinis \
	  tests/test_scaleout.py::test_paper_generic_set_split_equals_bertinis \
	  tests/test_framework_map.py \
	  tests/test_framework_folds.py \
	  tests/test_numbers_and_limits.py::test_map_through_a_point_at_1e_05 \
	  tests/test_monodromy.py tests/test_certify_agreement.py \
	  tests/test_real_route.py tests/test_total_degree_route.py tests/test_continuum.py \
	  tests/test_spatial_real.py tests/test_box_shares.py tests/test_paper_real.py \
	  tests/test_chart_map.py tests/test_real_route_property.py

bench: $(STAMP) phcpack
	$(BIN)/python bench/run_all.py

lint: $(STAMP)
	$(BIN)/ruff check cotm_bertini tests bench
	$(BIN)/ruff format --check cotm_bertini tests bench

format: $(STAMP)
	$(BIN)/ruff format cotm_bertini tests bench
	$(BIN)/ruff check --fix cotm_bertini tests bench

clean-runs:
	find runs -mindepth 1 -maxdepth 1 ! -name README.md -exec rm -rf {} +

# The pictures of README.md and docs/design.md, docs/img/<name>.png, each made by the command on
# the line above its copy; run before a release (not in CI, not in `make test`). Every command
# writes into a scratch folder with an empty cache of its own (so nothing stale is drawn); only
# the PNG is kept, the folder is removed. About 2 minutes on 2 cores, most of it the map.
# (docs/img/explore-plan.png is a browser screenshot taken by tests/test_explore.py.)
.PHONY: figures
FIGURES_TMP ?= /tmp/cotm-bertini-figures
figures: export COTM_CACHE := $(FIGURES_TMP)/cache
figures: $(STAMP)
	rm -rf $(FIGURES_TMP) && mkdir -p $(FIGURES_TMP) docs/img
	$(CLI) solve case3 --out $(FIGURES_TMP)/case3
	cp $(FIGURES_TMP)/case3/latest/configurations.png docs/img/case3-equilibria.png
	$(CLI) sweep --param L01 --from 0 --to 12 --points 241 --out $(FIGURES_TMP)/sweep
	cp $(FIGURES_TMP)/sweep/sweep-L01-*/bifurcation.png docs/img/sweep-L01.png
	$(CLI) map --out $(FIGURES_TMP)/map
	cp $(FIGURES_TMP)/map/latest/map.png docs/img/design-map.png
	$(CLI) solve --framework examples/prism_slack.toml --out $(FIGURES_TMP)/prism
	cp $(FIGURES_TMP)/prism/latest/configurations.png docs/img/prism-slack-equilibria.png
	$(CLI) move --framework examples/zeeman.toml --set x=0.1 --state 1 --path y=-0.8,0.2,-0.8 --out $(FIGURES_TMP)/move
	cp $(FIGURES_TMP)/move/latest/move.png docs/img/zeeman-move.png
	$(CLI) plan --framework examples/zeeman.toml --set x=0.1 --set y=-0.25 --state 1 --goal 2 --param x --from -0.6 --to 0.8 --param2 y --from2 -0.8 --to2 0.2 --out $(FIGURES_TMP)/plan
	cp $(FIGURES_TMP)/plan/latest/plan.png docs/img/zeeman-plan.png
	rm -rf $(FIGURES_TMP)
