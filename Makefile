# Two commands are all the set-up a user needs:
#   make demo   installs what is missing, builds, runs the synthetic demo headless, writes
#               out/demo.png (rviz screenshot) and out/demo_report.md
#   make test   runs every test (gtest, rostest, pytest); exits non-zero if any fails
# Hardening (docs/development.md, "Hardening and CI"):
#   make test-sanitize   ASan+UBSan build (.ws-san) running the gtests and the pytests
#   make test-tsan       TSan build (.ws-tsan) running the gtests of the two-thread code
#   make fuzz            fixed-seed fuzz campaign (FUZZ_CASES=20000 by default, FUZZ_SEED=17)
#   make fuzz-sanitize   the binding part of that campaign against the sanitized module
#   make pip-check       pip install . in a fresh venv without ROS, then the pytests there
# Soaks (docs/benchmarks.md):
#   make soak            10-minute soaks of the costmap and TSDF nodelets (SOAK_MINUTES=10,
#                        SOAK_ONLY=costmap|tsdf): RSS and messages handled, out/soak.md
SHELL := /bin/bash
.DEFAULT_GOAL := help

.PHONY: help deps build install-check pip-check test test-sanitize test-tsan fuzz fuzz-sanitize demo bench bench-open3d bench-tsdf-accuracy soak lint clean

FUZZ_CASES ?= 20000
FUZZ_SEED ?= 17
SOAK_MINUTES ?= 10
SOAK_ONLY ?=

help:
	@echo "make demo | make test | make install-check | make pip-check | make test-sanitize | make test-tsan | make fuzz | make fuzz-sanitize | make bench | make bench-open3d | make bench-tsdf-accuracy | make soak | make build | make deps | make lint | make clean"

deps:
	@tools/install_deps.sh
	@tools/python_venv.sh

build: deps
	@tools/build.sh

test: build
	@tools/run_tests.sh

# An install space (.ws/install) and a smoke test run from it alone (tools/install_smoke.py).
install-check: build
	@tools/install_check.sh

test-sanitize: deps
	@tools/test_sanitize.sh

# ThreadSanitizer on the gtests of the code that shares work between threads (.ws-tsan).
test-tsan: deps
	@tools/test_tsan.sh

# pyproject.toml: the ROS-free core as a Python package (docs/python.md, "Python without ROS").
pip-check: deps
	@tools/pip_check.sh

# The message-check driver is built only here (EXCLUDE_FROM_ALL in CMakeLists.txt).
fuzz: build
	@source tools/env.sh && cd "$$WS" && catkin_make -j2 fuzz_message_checks > "$$WS/fuzz_build.log" 2>&1 \
		|| { tail -30 "$$WS/fuzz_build.log"; echo "fuzz: building fuzz_message_checks failed"; exit 1; }
	@source tools/env.sh && source_workspace && \
		python3 test/fuzz/fuzz.py --cases $(FUZZ_CASES) --seed $(FUZZ_SEED) --out out/fuzz

fuzz-sanitize: deps
	@tools/fuzz_sanitize.sh --cases $(FUZZ_CASES) --seed $(FUZZ_SEED)

demo: build
	@source tools/env.sh && source_workspace && python3 scripts/demo.py --out out

bench: build
	@source tools/env.sh && source_workspace && python3 bench/bench.py --out out

# TSDF integration side by side with Open3D 0.19 (installed into .ws/open3d-venv for this only).
bench-open3d: build
	@tools/open3d_venv.sh
	@source tools/env.sh && source_workspace && OMP_NUM_THREADS=1 \
		"$$WS/open3d-venv/bin/python" bench/bench_open3d.py

# TSDF mesh accuracy over scenes, lattice offsets and noise cases, ours next to Open3D 0.19
# (same venv as bench-open3d); every score in out/tsdf_accuracy.json. About 28 minutes on one core.
bench-tsdf-accuracy: build
	@tools/open3d_venv.sh
	@source tools/env.sh && source_workspace && OMP_NUM_THREADS=1 \
		"$$WS/open3d-venv/bin/python" bench/bench_tsdf_accuracy.py --json out/tsdf_accuracy.json

soak: build
	@source tools/env.sh && source_workspace && python3 bench/soak.py --out out \
		--minutes $(SOAK_MINUTES) $(if $(SOAK_ONLY),--only $(SOAK_ONLY))

lint: deps
	@tools/lint.sh

clean:
	rm -rf .ws .ws-san .ws-tsan out
