# Two set-up commands (see README.md): `make demo` runs the main job, `make test` the test suite.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test generate check bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[test]'
	touch $(STAMP)

generate: $(STAMP)
	$(BIN)/lagrange-gen models/*.py

check: $(STAMP)
	$(BIN)/lagrange-gen --check models/*.py

demo: generate
	$(BIN)/lagrange-gen simulate models/cart_pendulum.py --method midpoint --h 1e-3 --t-end 10 \
		--q0 0.1 0.5 --v0 0 0 --out out/cart_pendulum.npz --plot out/cart_pendulum.png

test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

clean:
	rm -rf $(VENV) out .pytest_cache
