# Two commands on a fresh machine: `make demo` and `make test`.
# torch==2.13.0 is installed FIRST, on its own: pip finds the CPU wheel on disk
# (pip's find-links). Anything that depends on torch installed before it would pull
# the newest torch from the registry together with several GB of CUDA packages.
# The ray extra is installed too: the tests build a dataset on a local Ray instance.

PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
STAMP  := $(VENV)/.installed
OUT    ?= demo_output

.PHONY: install demo test lint docs bench clean

$(PY):
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(PY)
	$(PIP) install --quiet --upgrade pip
	$(PIP) install --quiet "torch==2.13.0"
	$(PIP) install --quiet -e ".[dev,ray,docs]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(PY) -m gnngarment.demo --out $(OUT)

NODE_STAMP := node_modules/.installed

# The Khronos glTF validator (npm `gltf-validator`) checks our .glb exports in the tests.
$(NODE_STAMP): package.json package-lock.json
	npm ci --silent --no-audit --no-fund
	touch $(NODE_STAMP)

# The suite runs in TEST_WORKERS processes (pytest-xdist), whole test files to a worker so
# that module fixtures are built once; one torch thread each, since two workers already
# fill the two cores and a second thread per worker only waits for a descheduled one.
TEST_WORKERS ?= 2

# The docs site builds with --strict: a broken link, a missing page or an API entry whose
# docstring does not parse fails the target (mkdocs.yml).
DOCS_ENV := NO_MKDOCS_2_WARNING=1

test: $(STAMP) $(NODE_STAMP)
	$(VENV)/bin/ruff check .
	$(DOCS_ENV) $(VENV)/bin/mkdocs build --strict --quiet
	OMP_NUM_THREADS=1 $(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile

# Serves the docs site at http://127.0.0.1:8000, rebuilt on every change.
docs: $(STAMP)
	$(DOCS_ENV) $(VENV)/bin/mkdocs serve

lint: $(STAMP)
	$(VENV)/bin/ruff check .

bench: $(STAMP)
	$(PY) benchmarks/prepare_garment.py

clean:
	rm -rf $(VENV) $(OUT) node_modules .pytest_cache .ruff_cache build/site
