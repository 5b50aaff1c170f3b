# Two entry points for a newcomer: `make demo` and `make test`. Both first install what is missing:
# Debian packages (as root; otherwise the command to run is printed) and a virtual environment
# with the pinned Python packages of constraints.txt. Only the tests need the firmware's toolchain
# and its emulator (firmware/system-packages.txt) and a virtual X server for the live runs
# (tests/system-packages.txt): `make demo` leaves them out.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test

.PHONY: demo test test-all system test-system venv clean

system:
	@echo "== checking the Debian packages the rig needs (system-packages.txt)"
	@scripts/install-system-packages.sh system-packages.txt

test-system:
	@echo "== checking the Debian packages the tests need (system-packages.txt, firmware/ and tests/)"
	@scripts/install-system-packages.sh system-packages.txt firmware/system-packages.txt tests/system-packages.txt

venv: $(STAMP)

# pip's own lines (each package as it is collected, downloaded and installed) show while it works:
# the first install takes minutes.
$(STAMP): pyproject.toml setup.py analysis/_jpeg_region.c rig/devices/trackers/_readers.c constraints.txt
	@echo "== making a Python virtual environment in $(VENV)"
	$(PYTHON) -m venv $(VENV)
	@echo "== installing the rig and the Python packages pinned in constraints.txt into $(VENV) (minutes the first time: numpy, OpenCV, JAX, SciPy, matplotlib, and compiling the rig's two C extensions)"
	$(BIN)/pip install --progress-bar on -c constraints.txt -e .
	touch $(STAMP)

$(TEST_STAMP): $(STAMP)
	@echo "== installing the test tools pinned in constraints.txt (pytest, pytest-timeout, hypothesis and the notebook runner, and MkDocs for the documentation) into $(VENV)"
	$(BIN)/pip install --progress-bar on -c constraints.txt -e '.[test,docs]'
	touch $(TEST_STAMP)

demo: system $(STAMP)
	@echo "== running the demo: a simulated rig filmed and measured, into out/demo"
	$(BIN)/rig demo --out out/demo

# `make test` is what CI runs: every test but those marked slow (heavier variants of what the others
# cover: benchmark modes, whole tuning runs, an installed wheel); `make test-all` runs those too.
test: test-system $(TEST_STAMP)
	$(MAKE) -C firmware all test
	$(BIN)/python -m pytest -q -m "not slow"

test-all: test-system $(TEST_STAMP)
	$(MAKE) -C firmware all test
	$(BIN)/python -m pytest -q

clean:
	rm -rf $(VENV) out

# `make docs` builds the documentation site into out/site in strict mode (tests/test_docs.py builds it
# in CI); `make notebooks` installs Jupyter and executes both notebooks into out/notebooks.
DOCS_STAMP := $(VENV)/.installed-docs
NOTEBOOKS_STAMP := $(VENV)/.installed-notebooks

.PHONY: docs notebooks

$(DOCS_STAMP): $(STAMP)
	$(BIN)/pip install --quiet -c constraints.txt -e '.[docs]'
	touch $(DOCS_STAMP)

docs: system $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

$(NOTEBOOKS_STAMP): $(STAMP)
	@echo "installing Jupyter (nbconvert, ipykernel, notebook) into $(VENV)"
	$(BIN)/pip install --quiet -c constraints.txt -e '.[notebooks]'
	touch $(NOTEBOOKS_STAMP)

notebooks: system $(NOTEBOOKS_STAMP)
	$(BIN)/jupyter nbconvert --to notebook --execute --ExecutePreprocessor.timeout=600 --output-dir out/notebooks notebooks/*.ipynb
	@echo "executed notebooks in out/notebooks; open them with: $(BIN)/jupyter notebook notebooks/"
