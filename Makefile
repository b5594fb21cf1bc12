# Two commands on a fresh Debian machine: `make demo` and `make test`. Each installs what is
# missing (Debian packages, a virtual environment, the package), then runs. `make demo` installs
# only what the demo needs (the core's build dependencies and the runtime Python packages);
# `make test` adds the test packages (GoogleTest, Google Benchmark, pytest, Pinocchio, sympy).
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
PIP := $(PY) -m pip --disable-pip-version-check
APT_PYTHON_PACKAGES := python3-venv
APT_PACKAGES := libeigen3-dev libtomlplusplus-dev liborocos-kdl-dev liburdfdom-dev g++ make python3-venv python3-dev
APT_TEST_PACKAGES := libgtest-dev libbenchmark-dev chromium
CPP_BUILD := build/cpp
JOBS ?= 2
SOURCES := $(shell find cpp bindings python tests/cpp tests/consumer bench cmake -path bench/results -prune \
             -o -type f -print 2>/dev/null) \
           CMakeLists.txt pyproject.toml
# pip install of a list from pyproject.toml (one source of truth), read by the venv's Python when
# the recipe runs: $(call pip_list,runtime) for `dependencies`, $(call pip_list,test) for an extra
define pip_list
deps=(); while IFS= read -r d; do deps+=("$$d"); done < <($(PY) -c "import sys; \
tomllib = __import__('tomllib') if sys.version_info >= (3, 11) else __import__('pip._vendor.tomli', fromlist=['loads']); \
p = tomllib.load(open('pyproject.toml', 'rb'))['project']; \
print('\n'.join(p['dependencies'] if sys.argv[1] == 'runtime' else p['optional-dependencies'][sys.argv[1]]))" $(1)) \
  && [ $${#deps[@]} -gt 0 ] && echo "    $${deps[*]}" && $(PIP) install -q --progress-bar off "$${deps[@]}"
endef
say = @printf '\n==> %s\n' $(1)

.PHONY: demo test test-cpp test-python test-sanitize test-embedded test-without-papers bench docs stubs apt apt-test venv install install-test install-docs clean help

help:
	@echo "make demo   - install what is missing, then run 'mechbal demo' (output in out/demo)"
	@echo "make test   - install what is missing, then run the C++ tests (ctest) and pytest"
	@echo "make test-sanitize - the C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer"
	@echo "make test-embedded - cross-build the minimal core + examples/embedded for aarch64, run it under"
	@echo "             qemu-user on the PAMINSA case and the reaction-wheel arm and compare with the"
	@echo "             native build (1e-12)"
	@echo "make test-without-papers - delete every paper (Python, C++, bindings) in a copy of the sources,"
	@echo "             build the core, its C++ tests and the Python module there, run the general tests"
	@echo "make bench  - build and run the benchmarks"
	@echo "make docs   - build the user guide and API reference into build/site (MkDocs, offline)"
	@echo "make stubs  - regenerate python/mechbal/_core.pyi from the bindings (pybind11-stubgen)"
	@echo "make clean  - remove build outputs and the virtual environment"
	@echo "JOBS=N      - parallel compile jobs (default 2)"

demo: install
	$(call say,"Running the default case study: .venv/bin/mechbal demo --out out/demo")
	$(VENV)/bin/mechbal demo --out out/demo

test: test-cpp test-python

# ---- setup ------------------------------------------------------------------------------------
define apt_install
	@missing=""; for p in $(1); do \
	  dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  printf '\n==> Installing Debian packages:%s\n' "$$missing"; \
	  SUDO=""; [ "$$(id -u)" -ne 0 ] && SUDO="sudo"; \
	  $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	  $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing \
	    </dev/null || { echo "apt-get failed: install$$missing by hand"; exit 1; }; \
	fi
endef

# What a virtual environment needs (enough for `make docs`, which compiles nothing), then the
# compilers and libraries of the core.
$(VENV)/.stamp-apt-python:
	$(call apt_install,$(APT_PYTHON_PACKAGES))
	@mkdir -p $(VENV) && touch $@

apt: $(VENV)/.stamp-apt
$(VENV)/.stamp-apt: | $(VENV)/.stamp-apt-python
	$(call apt_install,$(APT_PACKAGES))
	@mkdir -p $(VENV) && touch $@

apt-test: $(VENV)/.stamp-apt-test
$(VENV)/.stamp-apt-test: | $(VENV)/.stamp-apt
	$(call apt_install,$(APT_TEST_PACKAGES))
	@touch $@

venv: $(VENV)/.stamp-venv
$(VENV)/.stamp-venv: pyproject.toml | $(VENV)/.stamp-apt-python
	$(call say,"Creating $(VENV) with the build tools (pip, scikit-build-core, pybind11, cmake, ninja)")
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PIP) install -q --upgrade pip
	$(PIP) install -q --progress-bar off "scikit-build-core>=0.10" "pybind11>=2.10" cmake ninja
	$(call say,"Installing the runtime Python packages")
	@$(call pip_list,runtime)
	@touch $@

# The build shows each compile step ([k/n] from ninja, through pip -v) and keeps the whole log.
install: $(VENV)/.stamp-install
$(VENV)/.stamp-install: $(SOURCES) | $(VENV)/.stamp-venv $(VENV)/.stamp-apt
	$(call say,"Building the C++ core and its Python module with $(JOBS) jobs (log: build/pip-install.log)")
	@mkdir -p build; set -o pipefail; start=$$(date +%s); \
	CMAKE_BUILD_PARALLEL_LEVEL=$(JOBS) $(PIP) install -v --no-build-isolation . 2>&1 \
	  | tee build/pip-install.log \
	  | grep --line-buffered -E '^ *\[[0-9]+/[0-9]+\] |^\*\*\* |^ *Successfully installed' \
	  | sed -u -e 's/^ *//' -e 's/^/    /' \
	  || { echo "pip install failed; the end of build/pip-install.log:"; tail -40 build/pip-install.log; exit 1; }; \
	echo "    built and installed in $$(( $$(date +%s) - start )) s"
	@touch $@

install-test: $(VENV)/.stamp-install-test
$(VENV)/.stamp-install-test: pyproject.toml | $(VENV)/.stamp-install $(VENV)/.stamp-apt-test
	$(call say,"Installing the test packages")
	@$(call pip_list,test)
	@touch $@

install-docs: $(VENV)/.stamp-install-docs
$(VENV)/.stamp-install-docs: pyproject.toml | $(VENV)/.stamp-venv
	$(call say,"Installing the documentation packages")
	@$(call pip_list,docs)
	@touch $@

# ---- docs and stubs ---------------------------------------------------------------------------
# The site is built from the sources and the checked-in stubs (no compiled module needed).
# No compiler and no network: the site reads the sources and the checked-in stubs, and loads
# nothing from elsewhere when viewed (the check below fails on a script or stylesheet from a URL).
docs: $(VENV)/.stamp-install-docs
	$(call say,"Building the user guide and API reference: build/site/index.html")
	$(VENV)/bin/mkdocs build --strict -f mkdocs.yml 2>&1 | grep -v '^INFO ' ; test $${PIPESTATUS[0]} -eq 0
	@! grep -rlE '<(script|link)[^>]+(src|href)="(https?:)?//' build/site --include='*.html' \
	  || { echo "the site loads scripts or stylesheets from the network (files above)"; exit 1; }

# After changing a binding: regenerate the checked-in stubs (tests/python/test_typing.py fails
# until they match the bindings).
stubs: install $(VENV)/.stamp-install-test
	$(PY) tools/stubgen.py

# ---- tests ------------------------------------------------------------------------------------
$(CPP_BUILD)/build.ninja: | $(VENV)/.stamp-venv $(VENV)/.stamp-apt-test
	$(VENV)/bin/cmake -S . -B $(CPP_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) -DMECHBAL_BUILD_TESTS=ON

test-cpp: $(CPP_BUILD)/build.ninja
	$(VENV)/bin/cmake --build $(CPP_BUILD) -j $(JOBS)
	$(VENV)/bin/ctest --test-dir $(CPP_BUILD) --output-on-failure -j $(JOBS)

test-python: install $(VENV)/.stamp-install-test
	$(PY) -m pytest -q tests/python

# ---- sanitizers: the C++ tests built with ASan + UBSan in their own build dir (Debug, so Eigen's
# assertions are on; -O1 keeps the run short). Any report fails the run. The consumer tests
# (install + find_package from a plain build: install_and_consume, embedded_example) are not
# instrumented and are left to `make test`.
SAN_BUILD := build/sanitize
SAN_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
$(SAN_BUILD)/build.ninja: | $(VENV)/.stamp-venv $(VENV)/.stamp-apt
	$(VENV)/bin/cmake -S . -B $(SAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) -DMECHBAL_BUILD_TESTS=ON \
	  -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" -DCMAKE_CXX_FLAGS="$(SAN_FLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS="$(SAN_FLAGS)"

test-sanitize: $(SAN_BUILD)/build.ninja
	$(VENV)/bin/cmake --build $(SAN_BUILD) -j $(JOBS)
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  $(VENV)/bin/ctest --test-dir $(SAN_BUILD) --output-on-failure -j $(JOBS) \
	  -E "install_and_consume|embedded_example"

# ---- without papers: a paper is deleted by deleting its folders (python/mechbal/papers/<paper>,
# cpp/include/mechbal/papers, cpp/src/papers, bindings/papers). A copy of the sources (tracked and
# new files) with every paper deleted is built (core, C++ tests and the Python module, in one CMake
# build: MECHBAL_WITH_PAPERS defaults to OFF there), then its general C++ tests and the general
# Python tests run on it. A full build of its own: not part of `make test` (NOPAPERS_CPP_TESTS=OFF
# builds the core and the module only, and runs the Python tests).
NOPAPERS := build/without-papers
NOPAPERS_CPP_TESTS ?= ON
NOPAPERS_PYTESTS := tests/python/test_mechanism.py tests/python/test_spec.py tests/python/test_config.py \
                    tests/python/test_simulate.py tests/python/test_loops.py tests/python/test_passive.py \
                    tests/python/test_rnea.py tests/python/test_layers.py
test-without-papers: | $(VENV)/.stamp-install-test
	@start=$$(date +%s); rm -rf $(NOPAPERS)/src && mkdir -p $(NOPAPERS)/src && \
	git ls-files --cached --others --exclude-standard | grep -vE '^(cpp/include/mechbal/papers|cpp/src/papers|bindings/papers|python/mechbal/papers/[^_/][^/]*)/' \
	  | while IFS= read -r f; do [ -e "$$f" ] && printf '%s\n' "$$f"; done | tar -cf - -T - | tar -xf - -C $(NOPAPERS)/src && \
	echo "$$start" > $(NOPAPERS)/start
	$(call say,"Building the sources without any paper ($(NOPAPERS)/src) with $(JOBS) jobs")
	$(VENV)/bin/cmake -S $(NOPAPERS)/src -B $(NOPAPERS)/build -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) -DMECHBAL_BUILD_TESTS=$(NOPAPERS_CPP_TESTS) \
	  -DMECHBAL_BUILD_PYTHON=ON -DPython_EXECUTABLE=$(abspath $(PY)) >/dev/null
	@grep -q "MECHBAL_WITH_PAPERS:BOOL=OFF" $(NOPAPERS)/build/CMakeCache.txt || { echo "papers still found"; exit 1; }
	$(VENV)/bin/cmake --build $(NOPAPERS)/build -j $(JOBS)
	if [ "$(NOPAPERS_CPP_TESTS)" = ON ]; then $(VENV)/bin/ctest --test-dir $(NOPAPERS)/build --output-on-failure -j $(JOBS); fi
	cp $(NOPAPERS)/build/_core*.so $(NOPAPERS)/src/python/mechbal/
	cd $(NOPAPERS)/src && PYTHONPATH=$$PWD/python MPLBACKEND=Agg $(abspath $(PY)) -m pytest -q -p no:cacheprovider \
	  $(NOPAPERS_PYTESTS)
	@echo "    test-without-papers took $$(( $$(date +%s) - $$(cat $(NOPAPERS)/start) )) s"

# ---- embedded: the minimal core (no KDL, no urdfdom: Eigen + toml++ only) and examples/embedded,
# built natively and cross-built for aarch64 (Debian's g++-aarch64-linux-gnu), installed, then the
# example runs the balanced PAMINSA under computed torque and the reaction-wheel arm under its
# reactionless controller (with a computed-torque stage) for EMBEDDED_TICKS ticks natively and
# under qemu-user; each pair of tick traces must agree to 1e-12 of the scale of the torques and of
# the shaking wrench (force and moment together: the balanced design's shaking force, and the wheel
# arm's cancelled moment about z, are rounding noise). The generated variant (generated.cpp: the
# balanced PAMINSA's generated header, nothing else) runs its closed ticks on the same motion, both
# builds, against the library's answer (1e-9) and each other (1e-12).
EMBEDDED_BUILD := build/embedded
EMBEDDED_TICKS ?= 300
EMBEDDED_CASE := python/mechbal/papers/paminsa/cases/paminsa-linkage.toml examples/embedded/paminsa-control.toml
EMBEDDED_WHEEL_CASE := python/mechbal/cases/reaction-wheel-arm.toml examples/embedded/reaction-wheel-control.toml
EMBEDDED_GENERATED_CASE := python/mechbal/papers/paminsa/cases/paminsa-linkage.toml
APT_EMBEDDED_PACKAGES := g++-aarch64-linux-gnu qemu-user
define embedded_build
	$(VENV)/bin/cmake -S . -B $(EMBEDDED_BUILD)/$(1)/core -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) $(2) -DMECHBAL_WITH_KDL=OFF \
	  -DMECHBAL_WITH_URDF=OFF -DMECHBAL_BUILD_TESTS=OFF -DMECHBAL_BUILD_PYTHON=OFF >/dev/null
	$(VENV)/bin/cmake --build $(EMBEDDED_BUILD)/$(1)/core -j $(JOBS)
	$(VENV)/bin/cmake --install $(EMBEDDED_BUILD)/$(1)/core --prefix $(abspath $(EMBEDDED_BUILD)/$(1)/prefix) >/dev/null
	$(VENV)/bin/cmake -S examples/embedded -B $(EMBEDDED_BUILD)/$(1)/example -G Ninja \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) $(2) \
	  -DMECHBAL_GENERATED_CASE=$(abspath $(EMBEDDED_GENERATED_CASE)) -DMECHBAL_PYTHON=$(abspath $(PY)) \
	  -DCMAKE_PREFIX_PATH=$(abspath $(EMBEDDED_BUILD)/$(1)/prefix) >/dev/null
	$(VENV)/bin/cmake --build $(EMBEDDED_BUILD)/$(1)/example -j $(JOBS)
endef

test-embedded: | $(VENV)/.stamp-install
	$(call apt_install,$(APT_EMBEDDED_PACKAGES))
	@start=$$(date +%s); echo "$$start" > $(EMBEDDED_BUILD).start 2>/dev/null || { mkdir -p build; echo "$$start" > $(EMBEDDED_BUILD).start; }
	$(call say,"Native minimal core (KDL and URDF off) and examples/embedded")
	$(call embedded_build,native,)
	$(call say,"aarch64 cross-build of the same")
	$(call embedded_build,aarch64,-DCMAKE_TOOLCHAIN_FILE=$(abspath cmake/aarch64-linux-gnu.cmake))
	@readelf -h $(EMBEDDED_BUILD)/aarch64/example/mechbal_embedded 2>/dev/null | grep -q AArch64 \
	  || { echo "the cross-built example is not an aarch64 executable"; exit 1; }
	$(call say,"Running $(EMBEDDED_TICKS) ticks of the balanced PAMINSA natively and under qemu-aarch64")
	$(EMBEDDED_BUILD)/native/example/mechbal_embedded $(EMBEDDED_CASE) --ticks $(EMBEDDED_TICKS) --no-sleep \
	  --trace $(EMBEDDED_BUILD)/native.trace
	qemu-aarch64 -L /usr/aarch64-linux-gnu $(EMBEDDED_BUILD)/aarch64/example/mechbal_embedded $(EMBEDDED_CASE) \
	  --ticks $(EMBEDDED_TICKS) --no-sleep --trace $(EMBEDDED_BUILD)/aarch64.trace
	python3 tools/compare_traces.py $(EMBEDDED_BUILD)/native.trace $(EMBEDDED_BUILD)/aarch64.trace 1e-12 6,6
	$(call say,"Running $(EMBEDDED_TICKS) ticks of the reaction-wheel arm (reactionless) natively and under qemu-aarch64")
	$(EMBEDDED_BUILD)/native/example/mechbal_embedded $(EMBEDDED_WHEEL_CASE) --ticks $(EMBEDDED_TICKS) --no-sleep \
	  --trace $(EMBEDDED_BUILD)/native-wheel.trace
	qemu-aarch64 -L /usr/aarch64-linux-gnu $(EMBEDDED_BUILD)/aarch64/example/mechbal_embedded $(EMBEDDED_WHEEL_CASE) \
	  --ticks $(EMBEDDED_TICKS) --no-sleep --trace $(EMBEDDED_BUILD)/aarch64-wheel.trace
	python3 tools/compare_traces.py $(EMBEDDED_BUILD)/native-wheel.trace $(EMBEDDED_BUILD)/aarch64-wheel.trace 1e-12 3,6
	$(call say,"The generated variant (examples/embedded/generated.cpp, the header of $(EMBEDDED_GENERATED_CASE)): natively and under qemu-aarch64")
	$(PY) tools/generated_motion.py $(EMBEDDED_GENERATED_CASE) $(EMBEDDED_BUILD)/generated.motion \
	  $(EMBEDDED_BUILD)/library.trace --ticks $(EMBEDDED_TICKS)
	$(EMBEDDED_BUILD)/native/example/mechbal_embedded_generated $(EMBEDDED_BUILD)/generated.motion \
	  --trace $(EMBEDDED_BUILD)/native-generated.trace
	qemu-aarch64 -L /usr/aarch64-linux-gnu $(EMBEDDED_BUILD)/aarch64/example/mechbal_embedded_generated \
	  $(EMBEDDED_BUILD)/generated.motion --trace $(EMBEDDED_BUILD)/aarch64-generated.trace
	python3 tools/compare_traces.py $(EMBEDDED_BUILD)/native-generated.trace $(EMBEDDED_BUILD)/library.trace 1e-9 6,6
	python3 tools/compare_traces.py $(EMBEDDED_BUILD)/native-generated.trace $(EMBEDDED_BUILD)/aarch64-generated.trace 1e-12 6,6
	@echo "    test-embedded took $$(( $$(date +%s) - $$(cat $(EMBEDDED_BUILD).start) )) s"

# ---- benchmarks (never part of `make test`; own build dir so test and bench builds don't fight) --
BENCH_BUILD := build/bench
BENCH_RUN := $(BENCH_BUILD)/results
BENCH_FLAGS ?= --benchmark_repetitions=7 --benchmark_min_time=0.05 \
               --benchmark_report_aggregates_only=true --tail_samples=20000
LOOP_SECONDS ?= 5
LOOP_PAMINSA_SECONDS ?= 2
LOOP_GENERAL_SECONDS ?= 3
# the loops poll the clock for the last LOOP_SPIN_US before each release (bench/README.md)
LOOP_SPIN_US ?= 1000

$(BENCH_BUILD)/build.ninja: | $(VENV)/.stamp-venv $(VENV)/.stamp-apt
	$(VENV)/bin/cmake -S . -B $(BENCH_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_MAKE_PROGRAM=$(abspath $(VENV)/bin/ninja) -DMECHBAL_BUILD_TESTS=OFF \
	  -DMECHBAL_BUILD_BENCH=ON

bench: install $(VENV)/.stamp-apt-test $(BENCH_BUILD)/build.ninja
	$(VENV)/bin/cmake --build $(BENCH_BUILD) -j $(JOBS)
	@mkdir -p $(BENCH_RUN)
	$(BENCH_BUILD)/bench/mechbal-bench $(BENCH_FLAGS) --tail_out=$(BENCH_RUN)/tail.json \
	  --benchmark_out=$(BENCH_RUN)/gbench.json --benchmark_out_format=json
	$(BENCH_BUILD)/bench/mechbal-loop --seconds $(LOOP_SECONDS) --rate 1000 --rt --spin-us $(LOOP_SPIN_US) \
	  --json $(BENCH_RUN)/loop.json
	$(BENCH_BUILD)/bench/mechbal-loop --seconds $(LOOP_PAMINSA_SECONDS) --rate 1000 --rt --spin-us $(LOOP_SPIN_US) \
	  --workload paminsa --json $(BENCH_RUN)/loop_paminsa.json
	$(BENCH_BUILD)/bench/mechbal-loop --seconds $(LOOP_GENERAL_SECONDS) --rate 1000 --rt --spin-us $(LOOP_SPIN_US) \
	  --workload paminsa_general --json $(BENCH_RUN)/loop_paminsa_general.json
	$(BENCH_BUILD)/bench/mechbal-loop --seconds $(LOOP_GENERAL_SECONDS) --rate 1000 --rt --spin-us $(LOOP_SPIN_US) \
	  --workload reactionless_general --json $(BENCH_RUN)/loop_reactionless_general.json
	$(PY) bench/bench_python.py --out $(BENCH_RUN)/python.json
	$(PY) bench/bench_plan.py --out bench/results/plan.json
	$(PY) bench/merge_results.py --gbench $(BENCH_RUN)/gbench.json --tail $(BENCH_RUN)/tail.json \
	  --loop $(BENCH_RUN)/loop.json --loop-paminsa $(BENCH_RUN)/loop_paminsa.json --python $(BENCH_RUN)/python.json \
	  --loop-extra paminsa_general=$(BENCH_RUN)/loop_paminsa_general.json \
	  --loop-extra reactionless_general=$(BENCH_RUN)/loop_reactionless_general.json \
	  --out-json bench/results/latest.json --out-md bench/results/latest.md

clean:
	rm -rf build $(VENV) out
