# hrg_gyro: the two set-up commands (README) and the benchmark entry point.
#   make run    install missing Debian packages, build, run the main job, print the summary
#   make test   install, build, run every unit test and rostest, then catkin_test_results
#   make unit   install, build the gtest binaries alone (the core's, one per concept folder, the tools',
#               the bag writer's, the fuzz corpus's) and run them, no master, no rostest: the daily loop
#               (UNIT=alignment,... selects binaries, GTEST_FILTER cases)
#   make bench  install, build, run the benchmarks
#   make soak   1 simulated h at 10 kHz through the nodes (sim clock, 2x), memory and drops watched
#   make fuzz   libFuzzer + ASan/UBSan on the parameter loader and the sample path (FUZZ_SECONDS each)
#   make figures  the main job, then the documentation figures docs/figures/*.png from its output
#                 (with a screenshot of its HTML calibration report)
# Everything builds in .ws/, a catkin workspace inside the checkout (ignored by git) whose
# src/hrg_gyro is a folder of links to this directory's entries, the workspace excepted (see
# scripts/link_workspace.sh); source .ws/devel/setup.bash to use the package.
SHELL := /bin/bash
.SHELLFLAGS := -eo pipefail -c
ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
WS := $(ROOT)/.ws
# Debian's python3 has catkin_pkg; a pyenv python3 earlier on PATH does not.
export PATH := /usr/bin:/bin:$(PATH)
CATKIN_ARGS := -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release
JOBS ?= $(shell nproc)
TEST_JOBS ?= $(JOBS)

.PHONY: deps build test unit run figures bench fuzz soak clean

deps:
	@bash $(ROOT)/scripts/install_deps.sh

build: deps
	@bash $(ROOT)/scripts/link_workspace.sh $(ROOT) $(WS)
	cd $(WS) && catkin_make $(CATKIN_ARGS) -j$(JOBS)
	@# catkin caches the environment at the first configure, before the generated Python messages
	@# exist; reconfigure once so tests and tools run with them on PYTHONPATH.
	@grep -q "dist-packages" $(WS)/build/catkin_generated/setup_cached.sh || \
	  (cd $(WS) && catkin_make $(CATKIN_ARGS) --force-cmake -j$(JOBS) > /dev/null)

test: build
	cd $(WS) && catkin_make $(CATKIN_ARGS) -j$(JOBS) tests
	@# The tests side by side, TEST_JOBS at once: no two share a file, a port or a work directory (each
	@# rostest has its own master on a free port and its own directory under the build's test_work/).
	cd $(WS) && source devel/setup.bash && catkin_make $(CATKIN_ARGS) -j$(TEST_JOBS) run_tests
	@# The package as a user installs it (fresh prefix, only the install space sourced) and catkin_lint.
	bash $(ROOT)/test/install_space/run.sh $(WS)
	@# rosrun finds each documented program once, without a prompt or a warning (devel space sourced).
	cd $(WS) && source devel/setup.bash && ROS_TEST_RESULTS_DIR=$(WS)/build/test_results \
	  /usr/bin/python3 $(ROOT)/test/workspace_test.py
	@# Every C++ file formatted as .clang-format says; the fuzz build finds every core source.
	ROS_TEST_RESULTS_DIR=$(WS)/build/test_results /usr/bin/python3 $(ROOT)/test/source_format_test.py
	ROS_TEST_RESULTS_DIR=$(WS)/build/test_results /usr/bin/python3 $(ROOT)/test/fuzz/fuzz_sources_test.py
	@# No function in src/ or include/ over 80 lines.
	ROS_TEST_RESULTS_DIR=$(WS)/build/test_results /usr/bin/python3 $(ROOT)/test/source_function_length_test.py
	@# --verbose: a failed test's whole result file (its assertion and output) ends the log.
	cd $(WS) && catkin_test_results --verbose build/test_results

# The unit tests alone: their binaries and what they link (the core library), not the nodes.
CORE_TESTS := common model resonator signal estimation processing alignment calibration simulation integration
UNIT ?= $(CORE_TESTS) tools bag_writer fuzz_corpus
comma := ,
UNIT_TESTS := $(subst $(comma), ,$(UNIT))
GTEST_FILTER ?= *
unit: deps
	@bash $(ROOT)/scripts/link_workspace.sh $(ROOT) $(WS)
	cd $(WS) && catkin_make $(CATKIN_ARGS) -j$(JOBS) $(foreach t,$(UNIT_TESTS),hrg_gyro_$(t)_test)
	@cd $(WS) && failed=""; for t in $(UNIT_TESTS); do \
	  ./devel/lib/hrg_gyro/hrg_gyro_$${t}_test --gtest_filter='$(GTEST_FILTER)' || failed="$$failed $$t"; done; \
	  if [ -n "$$failed" ]; then echo "make unit: failed:$$failed"; exit 1; fi

run: build
	cd $(WS) && source devel/setup.bash && bash $(ROOT)/scripts/run_main_job.sh

# The documentation figures (README, docs/testing.md): K(theta) and D(theta) against the binned data,
# the nonlinearity before/after and an Allan deviation, from the run_output/ of the main job.
# Also the example report's first page (docs/test_engineer_workflow.md), as headless Chromium shows it.
figures: run
	cd $(WS) && source devel/setup.bash && /usr/bin/python3 $(ROOT)/scripts/make_doc_figures.py
	chromium --headless --disable-gpu --no-sandbox --hide-scrollbars --window-size=900,1700 \
	  --screenshot=$(ROOT)/docs/figures/example_report.png file://$(ROOT)/run_output/report.html 2> /dev/null

# Benchmarks: Google Benchmark core suites, calibration, offline and live pipelines, the live triad (about 17 min);
# figures in bench_output/results.md. BENCH_ONLY=core,... selects parts (see bench/run_benchmarks.py).
bench: build
	cd $(WS) && catkin_make $(CATKIN_ARGS) -j$(JOBS) hrg_gyro_benchmarks
	cd $(WS) && source devel/setup.bash && /usr/bin/python3 $(ROOT)/bench/run_benchmarks.py

# Soak: SOAK_SECONDS (default 3600 simulated s) of 10 kHz through driver_sim, processor and calibrator
# with RSS sampled; SOAK_CLOCK=sim|wall, SOAK_TIME_SCALE (2); report in bench_output/soak (bench/soak.py).
soak: build
	cd $(WS) && source devel/setup.bash && /usr/bin/python3 $(ROOT)/bench/soak.py

# Fuzzing (clang from Debian): FUZZ_SECONDS per target (default 120), FUZZ_MERGE=1 to grow the
# checked-in corpus. `make test` replays the corpus without sanitizers (hrg_gyro_fuzz_corpus_test).
fuzz:
	@bash $(ROOT)/scripts/install_deps.sh clang-14 libclang-rt-14-dev
	bash $(ROOT)/scripts/run_fuzzers.sh

clean:
	rm -rf $(WS)
