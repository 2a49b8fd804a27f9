# Two commands are all the set-up a user needs:
#   make demo   installs what is missing, builds, runs the synthetic demo headless, writes
#               out/demo.png (rviz screenshot) and out/demo_report.md
#   make test   runs every test (gtest, rostest, pytest); exits non-zero if any fails
SHELL := /bin/bash
.DEFAULT_GOAL := help

.PHONY: help deps build test demo bench lint clean

help:
	@echo "make demo | make test | make bench | make build | make deps | make lint | make clean"

deps:
	@tools/install_deps.sh
	@tools/python_venv.sh

build: deps
	@tools/build.sh

test: build
	@tools/run_tests.sh

demo: build
	@source tools/env.sh && source_workspace && python3 scripts/demo.py --out out

bench: build
	@source tools/env.sh && source_workspace && python3 scripts/bench.py --out out

lint:
	@tools/lint.sh

clean:
	rm -rf .ws out
