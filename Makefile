# Two entry points for a newcomer: `make demo` and `make test`. Both first install what is missing:
# Debian packages (as root; otherwise the command to run is printed) and a virtual environment
# with the pinned Python packages of constraints.txt.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
SYSTEM_PACKAGE_LISTS := system-packages.txt $(wildcard firmware/system-packages.txt)

.PHONY: demo test system venv clean

system:
	@scripts/install-system-packages.sh $(SYSTEM_PACKAGE_LISTS)

venv: $(STAMP)

$(STAMP): pyproject.toml setup.py analysis/_jpeg_region.c constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet -c constraints.txt -e '.[test]'
	touch $(STAMP)

demo: system $(STAMP)
	$(BIN)/rig demo --out out/demo

test: system $(STAMP)
	$(MAKE) -C firmware all test
	$(BIN)/python -m pytest -q

clean:
	rm -rf $(VENV) out
