# The two commands a new user needs:  make reproduce  and  make test.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)

.PHONY: install reproduce check-report docs docs-check test test-all bench bench-all mutation lint clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	$(BIN)/python -m compileall -q src/grazing > /dev/null  # editable installs are not byte-compiled by pip
	rm -f $(VENV)/.installed-*
	touch $(STAMP)

install: $(STAMP)

reproduce: $(STAMP)
	$(BIN)/grazing report --out report

# Open report/index.html in headless Chromium: every image shown, every link live, and every plot area of
# every figure drawn on, its data inside its limits, its labels inside the image (needs chromium).
check-report: $(STAMP)
	test -f report/index.html || $(MAKE) reproduce
	$(BIN)/python -m grazing.report.browser report/index.html

# The documentation site, into docs/_build/html: warnings are errors; the tutorials are executed,
# their outputs cached in docs/_build/.jupyter_cache (a rebuild re-runs only the changed ones);
# MathJax is served from the site (no network to read it).
# The `docs` extra is installed here, once per change of pyproject.toml, not by `make install`.
DOCS_STAMP := $(VENV)/.docs-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)

$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[test,docs]"
	rm -f $(VENV)/.docs-*
	touch $(DOCS_STAMP)

# First docs/check_reference.py: every public function and class of the reference documents its
# parameters and returns and shows an example (the examples run with the tests' doctests).
docs: $(DOCS_STAMP)
	$(BIN)/python docs/check_reference.py
	$(BIN)/python -m sphinx -b html -W --keep-going -q docs docs/_build/html

# Every page of the built site in headless Chromium: no broken link, image or blank figure.
docs-check: docs
	$(BIN)/python -m grazing.report.browser docs/_build/html

# The tests run on every core (pytest-xdist), each test file on one worker: kernel compilation,
# most of a cold run, then proceeds in parallel.
PYTEST_PARALLEL = -n auto --dist loadfile

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks mutation
	$(BIN)/python -m pytest -m "not slow" $(PYTEST_PARALLEL)

test-all: $(STAMP)
	$(BIN)/ruff check src tests benchmarks mutation
	$(BIN)/python -m pytest $(PYTEST_PARALLEL)

bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[test,bench]"
	$(BIN)/python benchmarks/bench_simulate.py
	$(BIN)/python benchmarks/bench_sweep.py
	$(BIN)/python benchmarks/bench_grazing_curve.py

# Every benchmark the READMEs quote, into one saved run (benchmarks/results/latest.json, medians
# with their spread, the machine and the date), then the READMEs' tables rewritten from it.
# Run it on a quiet machine: about 15 minutes on 2 cores.
bench-all: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[test,bench]"
	$(BIN)/python benchmarks/run_all.py

# A random sample of 150 mutants of orbits/, attractors/ and core/period.py run against the default suite's
# tests of each (cosmic-ray, the `mutation` extra; not in CI): the score and the surviving mutants in
# mutation/results/report.md.  It mutates a temporary checkout of HEAD, not this tree.  30 to 60 s a
# mutant on two cores: one to two hours (docs/contributing.md has the last sample's score).
MUTANTS ?= 150

mutation: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[test,mutation]"
	rm -rf .mutation-tree && git worktree prune && git worktree add --detach .mutation-tree HEAD
	cd .mutation-tree && PYTHONPATH=$$PWD/src:$$PWD $(abspath $(BIN))/python mutation/run.py --count $(MUTANTS) --out $(CURDIR)/mutation/results
	git worktree remove --force .mutation-tree

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks mutation
	$(BIN)/ruff format --check src tests benchmarks mutation

clean:
	rm -rf $(VENV) report .pytest_cache docs/_build docs/api
