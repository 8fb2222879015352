# robokit courseware. The commands an instructor needs:
#   make course   build the course: run every lesson and solution notebook, write build/course/
#   make test     the everyday test-suite (no site builds, browser tests or whole hostile batches): minutes
#   make check    every test, the browser tests required, not skipped (.ci/run calls exactly this)
# Each target creates .venv on first use and installs both packages, editable, with their extras:
# the robokit library (pyproject.toml) and the robocourse course package (course/pyproject.toml),
# every dependency at the version constraints.txt pins (the versions that made the lessons' numbers).
#   make upgrade  install the newest versions the pyproject ranges allow and rewrite constraints.txt

PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.robokit-installed
PYTEST_ARGS ?=
# pytest-xdist over every core, a test module per unit of work; the tests sharing the fast course
# build make one unit, started early (tests/conftest.py)
XDIST  ?= -n auto --dist loadscope --no-loadscope-reorder
COURSE_ARGS ?=

.PHONY: course test check lab venv upgrade assignments bench clean

$(STAMP): pyproject.toml course/pyproject.toml constraints.txt
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[legged,arm,cholmod,dev]' -e './course[lab]'
	@touch $(STAMP)

venv: $(STAMP)

course: $(STAMP)
	$(BIN)/robocourse build $(COURSE_ARGS)

# both print their 15 slowest tests, so a test that grows shows in every run's log
test: $(STAMP)
	$(BIN)/python -m pytest $(XDIST) --durations=15 -m "not slow" $(PYTEST_ARGS)

check: $(STAMP)
	ROBOKIT_REQUIRE_BROWSER=1 $(BIN)/python -m pytest $(XDIST) --durations=15 --hypothesis-profile=check $(PYTEST_ARGS)

# A deliberate upgrade: the newest versions the pyproject ranges allow, resolved in a fresh venv (so
# nothing installed by hand is pinned); then update environment.yml's pins (tests/test_packaging.py
# names them), run `make course` and `make check`, and commit the new numbers with constraints.txt.
upgrade:
	rm -rf $(VENV)-upgrade && $(PYTHON) -m venv $(VENV)-upgrade
	$(VENV)-upgrade/bin/python -m pip install --quiet --upgrade pip
	$(VENV)-upgrade/bin/python -m pip install --quiet -e '.[legged,arm,cholmod,dev]' -e './course[lab]'
	{ grep '^#' constraints.txt; $(VENV)-upgrade/bin/python -m pip list --format=freeze --exclude-editable \
	  | grep -viE '^(pip|setuptools|wheel|robokit|robocourse)==' | sort -f; } > constraints.txt.new
	mv constraints.txt.new constraints.txt
	rm -rf $(VENV)-upgrade

lab: $(STAMP)
	$(BIN)/jupyter lab --notebook-dir=.

bench: $(STAMP)
	@for f in benchmarks/bench_*.py; do echo "== $$f"; PYTHONPATH=$(CURDIR) $(BIN)/python $$f || exit 1; done

clean:
	rm -rf build .pytest_cache
