# symcat developer targets. `make test` is the README's test command; CI runs it through .ci/run.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python

.PHONY: install generate check-generated compile test bench bench-peers demo docs clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --upgrade pip >/dev/null

install: $(PY)
	$(PY) -m pip install -e ".[test]"

## Re-derive every kernel in SymPy and regenerate generated/*.c and the manifest.
generate: install
	$(PY) -m symcat.codegen generate
	$(PY) -m symcat.codegen compile

## Fail if the committed generated code is stale (source changed, or a file edited by hand).
check-generated: install
	$(PY) -m symcat.codegen check

## Compile every kernel library into the cache.
compile: install
	$(PY) -m symcat.codegen compile

## Every test, in parallel on all cores (pytest-xdist), a test file at a time (its module fixtures
## built once), the files with slow tests first (tests/conftest.py). PYTEST_ARGS: more options.
test: install compile
	$(PY) -m pytest -q -n auto --dist loadfile --no-loadscope-reorder $(PYTEST_ARGS)

bench: install compile
	$(PY) -m bench.run

## The documentation (docs/_build/html/index.html): tutorials executed, warnings are errors.
## SYMCAT_DOCS_FULL=1 runs the tutorials on larger settings.
docs: compile
	$(PY) -m pip install -e ".[docs]" >/dev/null
	rm -rf docs/_build docs/tutorials_gallery
	$(PY) -m sphinx -W --keep-going -b html docs docs/_build/html
	@echo "make docs: open $(CURDIR)/docs/_build/html/index.html"

## symcat beside Exudyn on four problems (bench/report/peers.md). Exudyn is a bench-only
## dependency: installed here, into the same venv, never by `make install` or the tests.
EXUDYN ?= exudyn==1.13.6
bench-peers: install compile
	$(PY) -m pip install "$(EXUDYN)"
	OMP_NUM_THREADS=1 $(PY) -m bench.peers

demo: install
	$(VENV)/bin/symcat run cantilever --out out/cantilever
	@echo "make demo: the plot (cantilever.png), the ParaView file (cantilever.vtu) and summary.json are in $(CURDIR)/out/cantilever/"

clean:
	rm -rf out build *.egg-info .pytest_cache docs/_build docs/tutorials_gallery
	rm -rf $${SYMCAT_CACHE:-$${XDG_CACHE_HOME:-$$HOME/.cache}/symcat}
