# beatlite: the two commands of a fresh machine are `make run` and `make test`.
# Both bootstrap .venv (Python 3.11) and install the project with its notebook and dev extras.

PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
VPY    := $(VENV)/bin/python
STAMP  := $(VENV)/.beatlite-installed
INTERACTIVE := $(VENV)/.beatlite-interactive

# Headless, deterministic defaults for the notebooks and tests (override on the command line).
export MPLBACKEND ?= Agg
export BEATLITE_THREADS ?= 1
export BEATLITE_MODE ?= lecture
export PYTHONHASHSEED ?= 0
# What bl.viz.save_figure and the animation players do with a figure that has an empty panel, text under 8 px at
# the saved size or two series in one colour (beatlite.viz.check): `make run` and `make test` fail on it.
FIGURE_CHECK ?= raise
# Training processes at once for `make checkpoints` / `make seeds` (1 torch thread each; 2 on an idle 2-core machine).
JOBS ?= 1
# Recipes `make seeds` trains and records (default: all).
ONLY ?=

.PHONY: run test test-fast lint lab site venv system-deps data checkpoints results seeds bench clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	@test -x $(VPY) || $(PYTHON) -m venv $(VENV)
	$(VPY) -m pip install --quiet --upgrade pip
	$(VPY) -m pip install --quiet -e ".[notebooks,dev]"
	@touch $(STAMP)

# The `interactive` extra (pyvista's trame backend, ipywidgets) for JupyterLab; `make run` and `make lab` add it.
$(INTERACTIVE): $(STAMP)
	$(VPY) -m pip install --quiet -e ".[notebooks,dev,interactive]"
	@touch $(INTERACTIVE)

# Debian packages needed at run/test time (offscreen OpenGL for pyvista, espeak-ng for the corpus
# generator). Installs them when running as root with apt-get, otherwise says what is missing.
system-deps:
	@bash scripts/system_deps.sh

## The main job: execute every notebook in order on data_samples/ and write build/.
run: $(STAMP) $(INTERACTIVE) system-deps
	BEATLITE_FIGURE_CHECK=$(FIGURE_CHECK) $(VPY) scripts/run_notebooks.py --out build

## The course site in build/site/ (works from file://, offline): index.html (the course map), every notebook as an
## offline page and as reveal.js slides, the guide, the figures, the student copies. Reuses the executed notebooks of
## `make run` when current and runs the others. Colab links: `make site COLAB_REPO=owner/name` (or a GitHub origin).
SITE_STAMP := $(VENV)/.beatlite-site
COLAB_REPO ?=
COLAB_BRANCH ?= main
$(SITE_STAMP): $(STAMP)
	$(VPY) -m pip install --quiet -e ".[notebooks,dev,site]"
	@touch $(SITE_STAMP)

site: $(SITE_STAMP) $(INTERACTIVE) system-deps
	$(VPY) scripts/build_site.py --build build --branch $(COLAB_BRANCH) $(if $(COLAB_REPO),--colab-repo $(COLAB_REPO))

## JupyterLab on working copies of the notebooks in build/lab/ (copied from LAB_FROM once; delete a copy to get a
## fresh one; copies that hold solutions are replaced by student copies, the old ones kept in build/lab/backup/:
## scripts/lab_copies.py). notebooks/ keeps the solutions and stays clean, and BEATLITE_BUILD=build/lab keeps the
## figures, tables and caches of interactive work away from `make run`'s build/. Students: `make lab LAB_FROM=build/student`.
LAB      ?= build/lab
LAB_FROM ?= notebooks
lab: $(INTERACTIVE) system-deps
	@mkdir -p $(LAB)
	@$(VPY) scripts/lab_copies.py $(LAB_FROM) $(LAB)
	BEATLITE_BUILD=$(abspath $(LAB)) BEATLITE_INTERACTIVE=on $(VPY) -m jupyter lab --notebook-dir=$(LAB) \
		$(if $(filter 0,$(shell id -u)),--allow-root) $(LAB_ARGS)

## The test suite: lint, unit tests, nbval over every notebook, then the doctests (Examples) of beatlite.
test: $(STAMP) system-deps lint
	BEATLITE_INTERACTIVE=off BEATLITE_FIGURE_CHECK=$(FIGURE_CHECK) $(VPY) -m pytest tests notebooks --nbval-lax \
		--nbval-cell-timeout=900 -p no:cacheprovider
	BEATLITE_INTERACTIVE=off BEATLITE_FIGURE_CHECK=$(FIGURE_CHECK) $(VPY) -m pytest --doctest-modules beatlite -p no:cacheprovider

## The quick loop while editing (about 2 minutes on 2 cores): lint, the unit tests not marked `slow` (no
## torchrun, no whole-recipe training, no notebooks), the doctests. `make test` (CI) runs everything.
test-fast: $(STAMP) system-deps lint
	BEATLITE_INTERACTIVE=off BEATLITE_FIGURE_CHECK=$(FIGURE_CHECK) $(VPY) -m pytest tests -m "not slow" -p no:cacheprovider -q
	BEATLITE_INTERACTIVE=off BEATLITE_FIGURE_CHECK=$(FIGURE_CHECK) $(VPY) -m pytest --doctest-modules beatlite -p no:cacheprovider -q

lint: $(STAMP)
	$(VPY) -m ruff check beatlite tests bench scripts
	$(VPY) -m ruff format --check beatlite tests bench scripts

## Regenerate the embedded corpus (needs espeak-ng).
data: $(STAMP) system-deps
	$(VPY) -m beatlite.synth --out data_samples

## Retrain every shipped checkpoint on data_samples/ (recipes in beatlite/train/recipes.py).
checkpoints: $(STAMP)
	$(VPY) -m beatlite.train retrain-all --jobs $(JOBS)

## The model results table on the data_samples test split (build/results_models.md).
results: $(STAMP)
	$(VPY) -m beatlite.train results

## Train every recipe with seeds 2021-2023 (build/seeds/), ship each row's median-FGD seed to checkpoints/
## and record the mean ± sd table in checkpoints/results_seeds.md/.json (about 2 h with JOBS=2 on 2 idle cores).
## `make seeds ONLY="NAME ..."`: only these recipes' rows, recorded into the table beside the others'.
## A checkpoint in build/seeds/ that its recipe would train again is reused; `FORCE=1` retrains it (after a code
## change that leaves the recipe as it was).
seeds: $(STAMP)
	$(VPY) -m beatlite.train seeds --jobs $(JOBS) --ship --out checkpoints/results_seeds $(if $(ONLY),--only $(ONLY)) $(if $(FORCE),--force)

## Speed benchmarks (run on demand; they print ratios against the named alternatives).
bench: $(STAMP)
	@for b in bench/bench_*.py; do echo "== $$b"; $(VPY) $$b || exit 1; done

clean:
	rm -rf build .pytest_cache .ruff_cache
