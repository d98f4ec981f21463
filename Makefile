# The two commands of the README. Both install missing Debian packages first.
JOBS ?= $(shell nproc)
FLEXFIT := build/release/apps/flexfit/flexfit
DEMO_OUT ?= out/demo

.PHONY: demo test test-sanitizer-long test-threads deps release asan tsan bench clean

deps:
	@scripts/install-deps.sh

# A build directory configured by another generator (before the presets chose Ninja) is remade.
release: deps
	@[ ! -f build/release/CMakeCache.txt ] || grep -qs 'CMAKE_GENERATOR:INTERNAL=Ninja' build/release/CMakeCache.txt || rm -rf build/release
	@cmake --preset release >/dev/null
	@cmake --build --preset release -j $(JOBS)

asan: deps
	@[ ! -f build/asan/CMakeCache.txt ] || grep -qs 'CMAKE_GENERATOR:INTERNAL=Ninja' build/asan/CMakeCache.txt || rm -rf build/asan
	@cmake --preset asan >/dev/null
	@cmake --build --preset asan -j $(JOBS)

VIEWER := build/release/apps/viewer/flexfit-viewer

# The thesis's container experiment. With a display: the viewer on the ball-through-torus
# scene. Without one (or when the window cannot open): the scene and the whole Table 4.5
# headless, and a picture of the scene in contact rendered with EGL (no X server needed).
demo: release
	@if [ -n "$$DISPLAY" ] && $(VIEWER) examples/ball_torus.toml; then exit 0; fi; \
	set -e; mkdir -p $(DEMO_OUT); \
	$(FLEXFIT) run examples/ball_torus.toml --out $(DEMO_OUT)/ball_torus; \
	$(FLEXFIT) experiment ball-torus --out $(DEMO_OUT)/ball-torus; \
	$(VIEWER) examples/ball_torus.toml --egl --frames 20 --screenshot $(DEMO_OUT)/viewer.png \
	  || echo "demo: no EGL rendering here, skipped $(DEMO_OUT)/viewer.png"; \
	echo "demo: results in $(DEMO_OUT)/ (ball_torus/: metrics.csv, summary.json; ball-torus/: summary.md, *.png; viewer.png)"

# The whole suite in Release, and again under AddressSanitizer + UBSan but for the sanitizer
# run's longest tests (tests/sanitizer_long.txt), which test-sanitizer-long runs (CI runs both).
# Names matched exactly: dots escaped, blank and comment lines left out, a name followed by the
# end or by the space before a parameterized test's GetParam comment.
SANITIZER_LONG := ^($(shell grep -v -e '^\#' -e '^ *$$' tests/sanitizer_long.txt | sed 's/[.]/\\./g' | paste -sd'|'))( |$$)
test: release asan
	ctest --preset release -j $(JOBS)
	ctest --preset asan -j $(JOBS) -E '$(SANITIZER_LONG)'

test-sanitizer-long: asan
	ctest --preset asan -j $(JOBS) -R '$(SANITIZER_LONG)' --no-tests=error

# The tests that run threads (tests/threads.txt) under ThreadSanitizer: only the programs that
# hold them are built (the tsan build preset's targets). CI runs it after make test.
tsan: deps
	@cmake --preset tsan >/dev/null
	@cmake --build --preset tsan -j $(JOBS)

THREADS := ^($(shell grep -v -e '^\#' -e '^ *$$' tests/threads.txt | sed 's/[.]/\\./g' | paste -sd'|'))( |$$)
test-threads: tsan
	ctest --preset tsan -j $(JOBS) -R '$(THREADS)' --no-tests=error

BENCH_FLAGS := --benchmark_repetitions=12 --benchmark_enable_random_interleaving=true \
	--benchmark_report_aggregates_only=true --benchmark_min_time=0.2 \
	--benchmark_out_format=csv
bench: release
	@scripts/install-deps.sh
	@cmake --build --preset release --target benchmarks -j $(JOBS)
	build/release/bench/bench_msd_step $(BENCH_FLAGS) --benchmark_out=bench/results/msd_step.csv
	/usr/bin/python3 tools/bench_ratios.py bench/results/msd_step.csv --prefixes BM_FlexfitFullStep BM_NaiveFullStep
	/usr/bin/python3 tools/bench_ratios.py bench/results/msd_step.csv --prefixes BM_FlexfitFullStep BM_NaiveFullStep --statistic min
	/usr/bin/python3 tools/bench_ratios.py bench/results/msd_step.csv --prefixes BM_FlexfitAvx2 BM_NaiveFullStep
	/usr/bin/python3 tools/bench_ratios.py bench/results/msd_step.csv --prefixes BM_FlexfitScalar BM_NaiveFullStep
	build/release/bench/bench_part_step $(BENCH_FLAGS) --benchmark_out=bench/results/part_step.csv
	build/release/bench/bench_part_ratios $(BENCH_FLAGS) --benchmark_out=bench/results/part_ratios.csv
	/usr/bin/python3 tools/bench_ratios.py bench/results/part_ratios.csv --counter a_over_b
	build/release/bench/bench_collision $(BENCH_FLAGS) --benchmark_out=bench/results/collision.csv
	/usr/bin/python3 tools/bench_ratios.py bench/results/collision.csv \
	  --pair BM_FclObbrssQuery/0 BM_FlexfitQuery/0/1/4 --pair BM_FclObbrssQuery/1 BM_FlexfitQuery/1/1/4 \
	  --pair BM_FclObbrssQuery/2 BM_FlexfitQuery/2/1/4 --pair BM_FclObbrssQuery/3 BM_FlexfitQuery/3/1/4 \
	  --pair BM_FlexfitQuery/1/0/4 BM_FlexfitQuery/1/1/4 --pair BM_FclAabbRefit BM_FlexfitRefitLocal/1 \
	  --pair BM_FlexfitQuery/0/0/1 BM_FlexfitQuery/0/0/4 --pair BM_FlexfitQuery/0/1/1 BM_FlexfitQuery/0/1/4 \
	  --pair BM_FlexfitQuery/1/0/1 BM_FlexfitQuery/1/0/4 --pair BM_FlexfitQuery/1/1/1 BM_FlexfitQuery/1/1/4 \
	  --pair BM_BroadPhase/1 BM_BroadPhase/0 --pair BM_DeformingPairFclAabb/iterations:3/manual_time BM_DeformingPairFlexfit/iterations:3/manual_time \
	  --pair BM_DeformingPairFclObbrss/iterations:1/manual_time BM_DeformingPairFlexfit/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/0/1/4/iterations:3/manual_time BM_ToolIntoPart/0/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/1/1/4/iterations:3/manual_time BM_ToolIntoPart/1/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/2/1/4/iterations:3/manual_time BM_ToolIntoPart/2/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/0/2/1/iterations:3/manual_time BM_ToolIntoPart/0/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/1/2/1/iterations:3/manual_time BM_ToolIntoPart/1/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/2/2/1/iterations:3/manual_time BM_ToolIntoPart/2/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/0/0/1/iterations:3/manual_time BM_ToolIntoPart/0/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/0/1/1/iterations:3/manual_time BM_ToolIntoPart/0/1/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/1/0/1/iterations:3/manual_time BM_ToolIntoPart/1/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/1/1/1/iterations:3/manual_time BM_ToolIntoPart/1/1/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/2/0/1/iterations:3/manual_time BM_ToolIntoPart/2/0/4/iterations:3/manual_time \
	  --pair BM_ToolIntoPart/2/1/1/iterations:3/manual_time BM_ToolIntoPart/2/1/4/iterations:3/manual_time
	build/release/bench/bench_zone_coverage $(BENCH_FLAGS) --benchmark_out=bench/results/zone_coverage.csv
	/usr/bin/python3 tools/bench_ratios.py bench/results/zone_coverage.csv --counter chosen_over_whole
	build/release/bench/bench_implicit_step --benchmark_repetitions=3 --benchmark_report_aggregates_only=true --benchmark_min_time=0.2 --benchmark_out_format=csv --benchmark_out=bench/results/implicit_step.csv
	build/release/bench/bench_stiffness_limit --benchmark_out_format=csv --benchmark_out=bench/results/stiffness_limit.csv
	build/release/bench/bench_world --benchmark_repetitions=3 --benchmark_out_format=csv --benchmark_out=bench/results/world.csv

clean:
	rm -rf build out
