# Two commands on a fresh Debian machine: `make demo` and `make test`. Each installs what is
# missing (Debian packages, a virtual environment, the package), then runs.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
PIP := $(PY) -m pip --disable-pip-version-check
APT_PACKAGES := libeigen3-dev liborocos-kdl-dev liburdfdom-dev libgtest-dev libbenchmark-dev g++ make python3-venv python3-dev
CPP_BUILD := build/cpp
JOBS ?= 2
SOURCES := $(shell find cpp bindings python tests/cpp tests/consumer bench cmake -path bench/results -prune \
             -o -type f -print 2>/dev/null) \
           CMakeLists.txt pyproject.toml

.PHONY: demo test test-cpp test-python bench apt venv install clean help

help:
	@echo "make demo   - install what is missing, then run 'mechbal demo' (output in out/demo)"
	@echo "make test   - install what is missing, then run the C++ tests (ctest) and pytest"
	@echo "make bench  - build and run the benchmarks"
	@echo "make clean  - remove build outputs and the virtual environment"

demo: install
	$(VENV)/bin/mechbal demo --out out/demo

test: test-cpp test-python

# ---- setup ------------------------------------------------------------------------------------
apt: $(VENV)/.stamp-apt
$(VENV)/.stamp-apt:
	@missing=""; for p in $(APT_PACKAGES); do \
	  dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "Installing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" -ne 0 ] && SUDO="sudo"; \
	  $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	  $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing \
	    </dev/null || { echo "apt-get failed: install$$missing by hand"; exit 1; }; \
	fi
	@mkdir -p $(VENV) && touch $@

venv: $(VENV)/.stamp-venv
$(VENV)/.stamp-venv: pyproject.toml | $(VENV)/.stamp-apt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PIP) install -q --upgrade pip
	$(PIP) install -q "scikit-build-core>=0.10" "pybind11>=2.10" cmake ninja
	@touch $@

install: $(VENV)/.stamp-install
$(VENV)/.stamp-install: $(SOURCES) | $(VENV)/.stamp-venv
	$(PIP) install -q --no-build-isolation ".[test]"
	@touch $@

# ---- tests ------------------------------------------------------------------------------------
$(CPP_BUILD)/build.ninja: | $(VENV)/.stamp-venv
	$(VENV)/bin/cmake -S . -B $(CPP_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) -DMECHBAL_BUILD_TESTS=ON

test-cpp: $(CPP_BUILD)/build.ninja
	$(VENV)/bin/cmake --build $(CPP_BUILD) -j $(JOBS)
	$(VENV)/bin/ctest --test-dir $(CPP_BUILD) --output-on-failure -j $(JOBS)

test-python: install
	$(PY) -m pytest -q tests/python

# ---- benchmarks (never part of `make test`; own build dir so test and bench builds don't fight) --
BENCH_BUILD := build/bench
BENCH_RUN := $(BENCH_BUILD)/results
BENCH_FLAGS ?= --benchmark_repetitions=7 --benchmark_min_time=0.05 \
               --benchmark_report_aggregates_only=true --tail_samples=20000
LOOP_SECONDS ?= 5
LOOP_PAMINSA_SECONDS ?= 2

$(BENCH_BUILD)/build.ninja: | $(VENV)/.stamp-venv
	$(VENV)/bin/cmake -S . -B $(BENCH_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) -DMECHBAL_BUILD_TESTS=OFF \
	  -DMECHBAL_BUILD_BENCH=ON

bench: install $(BENCH_BUILD)/build.ninja
	$(VENV)/bin/cmake --build $(BENCH_BUILD) -j $(JOBS)
	@mkdir -p $(BENCH_RUN)
	$(BENCH_BUILD)/bench/mechbal-bench $(BENCH_FLAGS) --tail_out=$(BENCH_RUN)/tail.json \
	  --benchmark_out=$(BENCH_RUN)/gbench.json --benchmark_out_format=json
	$(BENCH_BUILD)/bench/mechbal-loop --seconds $(LOOP_SECONDS) --rate 1000 --rt \
	  --json $(BENCH_RUN)/loop.json
	$(BENCH_BUILD)/bench/mechbal-loop --seconds $(LOOP_PAMINSA_SECONDS) --rate 1000 --rt \
	  --workload paminsa --json $(BENCH_RUN)/loop_paminsa.json
	$(PY) bench/bench_python.py --out $(BENCH_RUN)/python.json
	$(PY) bench/merge_results.py --gbench $(BENCH_RUN)/gbench.json --tail $(BENCH_RUN)/tail.json \
	  --loop $(BENCH_RUN)/loop.json --loop-paminsa $(BENCH_RUN)/loop_paminsa.json --python $(BENCH_RUN)/python.json \
	  --out-json bench/results/latest.json --out-md bench/results/latest.md

clean:
	rm -rf build $(VENV) out
