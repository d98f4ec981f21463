# The two commands of the README. Both install missing Debian packages first.
JOBS ?= $(shell nproc)
FLEXFIT := build/release/apps/flexfit/flexfit
DEMO_OUT ?= out/demo

.PHONY: demo test deps release asan bench clean

deps:
	@scripts/install-deps.sh

release: deps
	@cmake --preset release >/dev/null
	@cmake --build --preset release -j $(JOBS)

asan: deps
	@cmake --preset asan >/dev/null
	@cmake --build --preset asan -j $(JOBS)

# Main job on the bundled default scene: the thesis's restoration experiment on torus1.
demo: release
	$(FLEXFIT) experiment restoration --out $(DEMO_OUT)
	@echo "demo: results in $(DEMO_OUT)/ (summary.md, *.csv, *.png)"

# The whole suite, in Release and again under AddressSanitizer + UBSan.
test: release asan
	ctest --preset release -j $(JOBS)
	ctest --preset asan -j $(JOBS)

bench: release
	build/release/bench/flexfit_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
	  --benchmark_min_time=0.5 --benchmark_out=bench/results/msd_step.csv --benchmark_out_format=csv
	/usr/bin/python3 tools/bench_ratios.py bench/results/msd_step.csv BM_FlexfitFullStep BM_NaiveFullStep

clean:
	rm -rf build out
