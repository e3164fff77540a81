# Two set-up commands (see README.md): `make demo` runs the main job, `make test` the test suite;
# `make docs` builds the documentation site into site/.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
# The package and its dependencies only (demo, generate, check); the test extra on top of it
# (numba-cuda, dask, hypothesis, pandas: make test, make docs).
DEMO_STAMP := $(VENV)/.installed-demo
STAMP := $(VENV)/.installed

.PHONY: demo test test-lowest-numba docs generate check bench clean

$(DEMO_STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e .
	touch $(DEMO_STAMP)

$(STAMP): $(DEMO_STAMP)
	$(BIN)/pip install --quiet -e '.[test]'
	touch $(STAMP)

generate: $(DEMO_STAMP)
	$(BIN)/lagrange-gen models/*.py

check: $(DEMO_STAMP)
	$(BIN)/lagrange-gen --check models/*.py

demo: generate
	$(BIN)/lagrange-gen simulate models/cart_pendulum.py --method midpoint --h 1e-3 --t-end 10 \
		--q0 0.1 0.5 --v0 0 0 --out out/cart_pendulum.npz --plot out/cart_pendulum.png

test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

# The documentation site (mkdocs.yml): the docs extra in the same venv, then a strict build (a
# warning, a broken link or a failing example in examples/ fails it) into site/.
DOCS_STAMP := $(VENV)/.installed-docs

$(DOCS_STAMP): $(STAMP)
	$(BIN)/pip install --quiet -e '.[docs]'
	touch $(DOCS_STAMP)

# The two variables quiet the notices mkdocs-material and a plugin print about a future mkdocs 2.
docs: $(DOCS_STAMP)
	DISABLE_MKDOCS_2_WARNING=true NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

# The smoke job on the lowest numba pyproject.toml allows (and the numpy it supports), in a venv
# and caches of its own: generate, every method once (against the portable glue), the jit
# layer's tests (the interpreted tier and native kernels included), the import rules.
LOWEST_VENV := .venv-lowest-numba
SMOKE_TESTS := tests/test_portable.py tests/test_jit_cache.py tests/test_jit_callee.py \
	tests/test_jit_speedups.py tests/test_numba_inline_copy.py tests/test_numba_typing_memo.py \
	tests/test_compile_gc.py tests/test_compile_message.py tests/test_interpreted.py \
	tests/test_native_kernels.py tests/test_architecture.py

$(LOWEST_VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(LOWEST_VENV)
	$(LOWEST_VENV)/bin/pip install --quiet --upgrade pip
	$(LOWEST_VENV)/bin/pip install --quiet "numba==0.59.1" "numpy<2" -e '.[test-base]'
	touch $@

test-lowest-numba: $(LOWEST_VENV)/.installed
	NUMBA_CACHE_DIR=$(LOWEST_VENV)/numba-cache LAGRANGE_GEN_PORTABLE_DIR=$(LOWEST_VENV)/portable \
		$(LOWEST_VENV)/bin/python -m pytest -q -n 2 --dist loadfile -p no:cacheprovider $(SMOKE_TESTS)

clean:
	rm -rf $(VENV) $(LOWEST_VENV) out site .pytest_cache
