# `make test` and `make demo` each build .venv on first use and install what they need.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
# mypy reads the package as it installs: agents/, train/ and benchmarks/ are subpackages
# of bearing_env (setuptools package-dir), so the view links them in under that name.
TYPECHECK_VIEW := $(VENV)/typecheck

.PHONY: test test-slow demo docs lint typecheck format format-check bench bench-slam clean native wheel stubs

# The native core's sources: any change rebuilds the extension before a test or demo runs,
# so no stale binary is ever tested.
NATIVE_SOURCES := CMakeLists.txt $(shell find csrc -type f 2>/dev/null)
NATIVE := $(VENV)/.native
# The build's settings for `make`: compiler warnings are errors.
BUILD_SETTINGS := -Ccmake.define.BEARING_ENV_WERROR=ON

$(STAMP): pyproject.toml constraints.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	# torch first, from the pin, so nothing later resolves a CUDA build
	$(PY) -m pip install --quiet -c constraints.txt torch==2.13.0
	# the build's own tools, pinned, so the editable install below builds without isolation
	$(PY) -m pip install --quiet -c constraints.txt scikit-build-core nanobind cmake ninja
	$(PY) -m pip install --quiet -c constraints.txt --no-build-isolation $(BUILD_SETTINGS) \
		-e ".[render,train,dev,ray,docs]"
	touch $(STAMP)
	touch $(NATIVE)

# Rebuild the extension (incrementally, in build/) when a C++ source changed.
$(NATIVE): $(STAMP) $(NATIVE_SOURCES)
	$(PY) -m pip install --quiet --no-build-isolation --no-deps $(BUILD_SETTINGS) -e .
	touch $(NATIVE)

native: $(NATIVE)

# Two workers, one per core; a test module stays on one worker (its fixtures run once).
test: $(NATIVE) lint typecheck format-check
	SDL_VIDEODRIVER=dummy $(PY) -m pytest -q -m "not slow" -n 2 --dist loadfile

# The tests `make test` leaves out (marked slow): each costs minutes (the sdist's own test
# run in a fresh venv, a real compile from an empty cache, a long seeded search, ...).
test-slow: $(NATIVE)
	SDL_VIDEODRIVER=dummy $(PY) -m pytest -q -m slow -n 2 --dist loadfile

demo: $(NATIVE)
	SDL_VIDEODRIVER=dummy $(PY) -m bearing_env.train.studies.demo
	SDL_VIDEODRIVER=dummy $(PY) -m bearing_env.train.compare.cli --quick

# The documentation site, incremental (tests/tools/test_docs_site.py builds it afresh with
# warnings as errors and checks its links and images).
docs: $(NATIVE)
	$(PY) -m sphinx -W --keep-going -q -j auto -b html docs docs/_build/html
	@echo "docs/_build/html/index.html"

# A wheel of this checkout for this machine, repaired by auditwheel to the manylinux tag
# its symbols allow (DIST/, default dist/): the wheel PyPI users install without a compiler.
DIST ?= dist
wheel: $(STAMP)
	rm -rf $(DIST)/raw
	$(PY) -m pip wheel --quiet --no-deps --no-build-isolation -Cbuild-dir=build/wheel \
		-w $(DIST)/raw .
	PATH="$(CURDIR)/$(VENV)/bin:$$PATH" $(PY) -m auditwheel repair -w $(DIST) $(DIST)/raw/*.whl
	rm -rf $(DIST)/raw

# The files generated from the built core: its type stub and the Python structs
# (bearing_env/_core.pyi, bearing_env/_schema.py); a test fails when they drift.
stubs: $(NATIVE)
	$(PY) -m tests.tools.generate_stubs

bench: $(NATIVE)
	$(PY) -m bearing_env.benchmarks.bench_env

bench-slam: $(NATIVE)
	$(PY) -m bearing_env.benchmarks.bench_slam

# The C++ sources' style (.clang-format), with the clang-format pinned in constraints.txt.
CPP_SOURCES := $(shell find csrc tests/cpp examples/cpp -name '*.cpp' -o -name '*.hpp' 2>/dev/null)
format-check: $(STAMP)
	$(VENV)/bin/clang-format --style=file --dry-run --Werror $(CPP_SOURCES)

format: $(STAMP)
	$(VENV)/bin/clang-format --style=file -i $(CPP_SOURCES)

lint: $(STAMP)
	$(PY) -m ruff check bearing_env agents train tests benchmarks docs/conf.py

typecheck: $(STAMP)
	rm -rf $(TYPECHECK_VIEW) && mkdir -p $(TYPECHECK_VIEW)/bearing_env
	ln -s $(CURDIR)/bearing_env/* $(CURDIR)/agents $(CURDIR)/train $(CURDIR)/benchmarks \
		$(TYPECHECK_VIEW)/bearing_env/
	cd $(TYPECHECK_VIEW) && $(CURDIR)/$(PY) -m mypy --config-file $(CURDIR)/pyproject.toml \
		--cache-dir $(CURDIR)/.mypy_cache -p bearing_env

clean:
	rm -rf $(VENV) .pytest_cache .hypothesis build *.egg-info docs/_build
