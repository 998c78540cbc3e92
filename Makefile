# `make demo`: the paper benchmark table.  `make test`: the whole test suite (CI runs exactly this).
# `make docs`: the documentation site in site/ (mkdocs build --strict).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
OUT ?= results/paper

.PHONY: demo test docs clean chromium compiler

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet --config-settings editable_mode=compat -e ".[test]"
	touch $@

demo: $(VENV)/.installed compiler
	$(BIN)/ocpkit bench paper --out $(OUT)

# pytest's options are in pyproject.toml: one pytest-xdist worker per CPU, the 20 slowest tests listed.
test: $(VENV)/.installed chromium compiler
	$(BIN)/python -m pytest -q

# The test extras include the docs packages (tests/test_docs.py builds the site too).
docs: $(VENV)/.installed
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

# The report and viewer tests take screenshots with headless Chromium (Debian's package; installed as root).
chromium:
	@command -v chromium >/dev/null || command -v chromium-browser >/dev/null || { [ "$$(id -u)" = 0 ] && \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; } || \
		{ echo "install chromium (apt-get install chromium) for the report and viewer tests"; exit 1; }

# The dynamics derivatives (once per robot), the collision rows' derivatives and the path search's collision test
# (once) are compiled to C (ocpkit.solvers.compiled): a C compiler (Debian's gcc, installed as root); without one
# the planner runs them uncompiled (CasADi's virtual machine, coal's collision test), the same answers, slower.
compiler:
	@command -v "$${CC:-cc}" >/dev/null || { [ "$$(id -u)" = 0 ] && apt-get update -qq && \
		DEBIAN_FRONTEND=noninteractive apt-get install -y -qq gcc; } || \
		echo "no C compiler: the derivatives and the collision test run uncompiled (slower); apt-get install gcc"

clean:
	rm -rf $(VENV) results site
