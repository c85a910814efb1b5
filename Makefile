# peopletrack — the README's commands. `make help` lists the targets.
CARGO ?= cargo
PYTHON ?= python3
VENV := target/py-venv

.PHONY: help eval datasets release test bench interop clean

PROFILE ?= quick

help:
	@echo "make eval      build (release), synthesize the default datasets if absent, run every pipeline, write out/ and out/REPORT.md"
	@echo "make datasets  synthesize every dataset in datasets/ whose logs are absent (PROFILE=quick|full)"
	@echo "make test      build and run every test (the CI command)"
	@echo "make bench     criterion benchmarks + the same reads in Python mcap-ros2-support, with ratios"
	@echo "make bench-mot tracking metrics: criterion on a synthetic sequence + py-motmetrics on the same files, with the ratio"
	@echo "make interop   check that Python mcap-ros2-support opens what we write, synthetic datasets included (throwaway venv)"
	@echo "make clean     remove build outputs and out/"

release:
	$(CARGO) build --release --locked

datasets: release
	./target/release/peopletrack synth --if-absent --profile $(PROFILE) datasets/*/scenario.toml

eval: datasets
	./target/release/peopletrack eval

test:
	$(CARGO) test --locked

# A throwaway virtual environment with the Python peers (not needed by the project itself).
$(VENV)/ok:
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check mcap==1.6.0 mcap-ros2-support==0.6.0
	touch $@

interop: $(VENV)/ok
	$(CARGO) run --quiet --release --example interop_fixture -- target/interop/fixture.mcap target/interop/expected.json
	$(VENV)/bin/python tools/check_mcap_ros2.py target/interop/fixture.mcap target/interop/expected.json
	$(MAKE) datasets
	$(VENV)/bin/python tools/check_synth_ros2.py ./target/release/peopletrack datasets/*/*.mcap

bench: $(VENV)/ok
	$(CARGO) bench --bench render -- --noplot
	$(CARGO) bench --bench read_decode -- --noplot
	$(VENV)/bin/python tools/bench_python_read.py target/bench-data/python_read.json
	$(VENV)/bin/python tools/bench_compare.py target/criterion target/bench-data/python_read.json
	$(MAKE) bench-mot

# py-motmetrics 1.4.0 calls np.asfarray, which numpy 2 removed: pin the last numpy 1 stack.
$(VENV)/mot-ok:
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check motmetrics==1.4.0 numpy==1.26.4 pandas==2.2.3 scipy==1.13.1
	touch $@

.PHONY: bench-mot
bench-mot: $(VENV)/mot-ok
	$(CARGO) bench --bench mot -- --noplot
	$(VENV)/bin/python tools/bench_motmetrics.py target/bench-data/mot target/criterion 3

clean:
	$(CARGO) clean
	rm -rf out
