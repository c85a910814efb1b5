# peopletrack — the README's commands. `make help` lists the targets.
CARGO ?= cargo
PYTHON ?= python3
VENV := target/py-venv
# py-motmetrics needs numpy 1, OpenCV 4.12 numpy 2: separate throwaway environments
VENV_MOT := target/py-venv-mot
# the notebook guide's readers (docs/notebooks.md)
VENV_NB := target/py-venv-notebook

.PHONY: help eval datasets release build-s3 test test-s3 bench interop notebook-check schemas audio-interop clean opencv-agreement stonesoup-agreement bench-gmm bench-multicam bench-laser wildtrack

PROFILE ?= quick

help:
	@echo "make eval      build (release), synthesize the default datasets if absent or stale, run every pipeline, write out/ and out/REPORT.md"
	@echo "make wildtrack import ../shared/real/wildtrack (if present) and run pipelines/real/s004_wildtrack.toml"
	@echo "make datasets  synthesize every dataset in datasets/ whose logs are absent or stale (PROFILE=quick|full)"
	@echo "make test      build and run every test (the CI command)"
	@echo "make build-s3  release build with object storage (s3:// logs and --out; docs/cluster.md)"
	@echo "make test-s3   a pipeline end to end against a local S3 server (Garage $(GARAGE_VERSION), installed once into $(TOOLS))"
	@echo "make bench     criterion benchmarks + the same reads in Python mcap-ros2-support, with ratios"
	@echo "make bench-mot tracking metrics: criterion on a synthetic sequence + py-motmetrics on the same files, with the ratio"
	@echo "make interop   check that Python mcap-ros2-support opens what we write, synthetic datasets included (throwaway venv)"
	@echo "make schemas   regenerate docs/schemas.md (every table's columns and types) from out/ of a finished make eval"
	@echo "make notebook-check  run docs/notebooks.md's Python (polars, pandas, DuckDB) against a fresh dataset_quality run (throwaway venv)"
	@echo "make audio-interop  read the BIRON audio back with Python mcap-ros2-support: a fixture and a biron_home session, samples equal (throwaway venv)"
	@echo "make opencv-agreement  pixel agreement of vision::gmm masks with OpenCV MOG2, fails below 100 % (throwaway venv)"
	@echo "make stonesoup-agreement  seed 001's PDAF (CV, CT) and IMM step by step against Stone Soup on real and synthetic scans, fails above 1e-9 (throwaway venv)"
	@echo "make bench-mlp         appearance-model training (10 splits) beside scikit-learn MLPRegressor, with the ratio"
	@echo "make bench-gmm         adaptive GMM frames/s beside OpenCV MOG2 on the same frames, with ratios"
	@echo "make bench-multicam    seed 004: frames/s of the whole s004_mohedano_multicam pipeline per camera and of the Gabor background alone"
	@echo "make bench-laser       laser legs + tracker (GNN, JPDA) scans/s on the real logs, one thread, as a multiple of real time and of decoding"
	@echo "make fuzz      cargo-fuzz (nightly): seed corpora from the real logs, then FUZZ_RUNS (10M) executions per target; make fuzz-install installs cargo-fuzz"
	@echo "make clean     remove build outputs and out/"

release:
	$(CARGO) build --release --locked

datasets: release
	./target/release/peopletrack synth --if-absent --profile $(PROFILE) datasets/*/scenario.toml
	@# re-identification's training split (seed 003, never scored): home_tour's tours 90-92
	[ -n "$(wildcard datasets/home_tour_train/*.mcap)" ] || ./target/release/peopletrack synth --profile train --out datasets/home_tour_train datasets/home_tour/scenario.toml

eval: datasets
	./target/release/peopletrack eval --profile $(PROFILE)
	$(MAKE) wildtrack

# WILDTRACK (real, ../shared/real/wildtrack): imported once into datasets/wildtrack/, then seed
# 004's 3-D stage on its annotated boxes (pipelines/real/s004_wildtrack.toml). SKIPPED when absent.
WILDTRACK_DIR ?= ../shared/real/wildtrack
wildtrack: release
	@if [ -d $(WILDTRACK_DIR)/annotations_positions ]; then \
	  [ -f datasets/wildtrack/wildtrack.mcap ] || ./target/release/peopletrack import wildtrack $(WILDTRACK_DIR) -o datasets/wildtrack/wildtrack.mcap; \
	  ./target/release/peopletrack run pipelines/real/s004_wildtrack.toml $(if $(filter full,$(PROFILE)),--out out/full,); \
	else echo "SKIPPED: $(WILDTRACK_DIR) is absent (WILDTRACK E6 run)"; fi

test:
	$(CARGO) test --locked

build-s3:
	$(CARGO) build --release --locked --features s3

# Object storage against a real S3 server: Garage, built from crates.io once into $(TOOLS)
# (about 21 minutes on 2 cores), then reused; tests/object_storage.rs starts it privately.
TOOLS ?= target/tools
GARAGE_VERSION := 2.5.0
$(TOOLS)/bin/garage:
	$(CARGO) install --locked garage --version $(GARAGE_VERSION) --root $(TOOLS)

test-s3: $(TOOLS)/bin/garage
	GARAGE_BIN=$(abspath $(TOOLS)/bin/garage) $(CARGO) test --locked --features s3 --test object_storage -- --nocapture

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

# Issue 34: docs/schemas.md, the schema of every table the pipelines write, generated from what a
# `make eval` left in out/ (Parquet footers) and the meanings in code; `make test` checks the
# pipelines its tests run against it. The real WILDTRACK pipeline joins when `make wildtrack` ran.
SCHEMA_PIPELINES := $(sort $(wildcard pipelines/*.toml)) $(if $(wildcard out/s004_wildtrack/tables),pipelines/real/s004_wildtrack.toml,)
schemas: release
	./target/release/peopletrack schemas $(SCHEMA_PIPELINES) --out out -o docs/schemas.md

# Issue 34: the notebook guide's code, block by block, against a fresh run of dataset_quality
# (hive-style per-session cache: out/<pipeline>/sessions/dataset=<d>/session=<s>/).
$(VENV_NB)/ok:
	$(PYTHON) -m venv $(VENV_NB)
	$(VENV_NB)/bin/pip install --quiet --disable-pip-version-check polars==1.44.2 pandas==2.3.3 pyarrow==26.0.1 duckdb==1.5.6
	touch $@

notebook-check: $(VENV_NB)/ok datasets
	rm -rf target/notebook-out
	./target/release/peopletrack run pipelines/dataset_quality.toml --out target/notebook-out
	$(VENV_NB)/bin/python tools/check_notebook_guide.py docs/notebooks.md target/notebook-out

# Issue 33: the two-microphone audio (audio_common_msgs) read back by mcap-ros2-support, sample
# for sample: a fixture of known samples, then a biron_home session against its `peopletrack wav`.
audio-interop: $(VENV)/ok release
	$(CARGO) run --quiet --release --example audio_fixture -- target/interop/audio.mcap target/interop/audio_expected.json
	$(VENV)/bin/python tools/check_audio_ros2.py fixture target/interop/audio.mcap target/interop/audio_expected.json
	./target/release/peopletrack synth --if-absent datasets/biron_home/scenario.toml
	./target/release/peopletrack wav datasets/biron_home/biron_home_00.mcap --topic /audio -o target/interop/biron_home_00.wav
	$(VENV)/bin/python tools/check_audio_ros2.py wav datasets/biron_home/biron_home_00.mcap /audio target/interop/biron_home_00.wav

bench: $(VENV)/ok
	$(CARGO) bench --bench render -- --noplot
	$(CARGO) bench --bench read_decode -- --noplot
	$(CARGO) build --release
	$(VENV)/bin/python tools/bench_python_read.py target/bench-data/python_read.json
	$(VENV)/bin/python tools/bench_compare.py target/criterion target/bench-data/python_read.json target/release/peopletrack
	$(MAKE) bench-mot
	$(MAKE) bench-gmm
	$(MAKE) bench-mlp
	$(MAKE) bench-multicam
	$(MAKE) bench-laser

# Laser people detection + tracking on the real logs in ../shared/real/laser (SKIPPED when absent).
bench-laser:
	$(CARGO) bench --bench laser -- --noplot

# Seed 004: the whole s004_mohedano_multicam processing per camera frame and the Gabor stage alone
# (a 2 s multicam_office session is synthesized into target/bench-data/ on first use).
bench-multicam:
	$(CARGO) bench --bench multicam -- --noplot

# py-motmetrics 1.4.0 calls np.asfarray, which numpy 2 removed: pin the last numpy 1 stack.
$(VENV_MOT)/mot-ok:
	$(PYTHON) -m venv $(VENV_MOT)
	$(VENV_MOT)/bin/pip install --quiet --disable-pip-version-check motmetrics==1.4.0 numpy==1.26.4 pandas==2.2.3 scipy==1.13.1
	touch $@

.PHONY: bench-mlp
bench-mlp: $(VENV)/sklearn-ok
	$(CARGO) bench --bench mlp -- --noplot
	$(VENV)/bin/python tools/bench_sklearn_mlp.py target/bench-data/mlp target/criterion

$(VENV)/sklearn-ok: $(VENV)/ok
	$(VENV)/bin/pip install --quiet --disable-pip-version-check scikit-learn==1.7.2 numpy==2.2.6
	touch $@

.PHONY: bench-mot
bench-mot: $(VENV_MOT)/mot-ok
	$(CARGO) bench --bench mot -- --noplot
	$(VENV_MOT)/bin/python tools/bench_motmetrics.py target/bench-data/mot target/criterion 3

# OpenCV's MOG2 as the reference for vision::gmm, in the same throwaway venv (own stamp).
$(VENV)/opencv-ok: $(VENV)/ok
	$(VENV)/bin/pip install --quiet --disable-pip-version-check opencv-python-headless==4.12.0.88 numpy==2.2.6
	touch $@

GMM_OUT := target/gmm-agreement
WAVING_TREES := ../shared/real/wallflower_waving_trees/WavingTrees

# Masks must be identical to OpenCV's: the check fails below 100 % pixel agreement.
opencv-agreement: $(VENV)/opencv-ok
	$(CARGO) run --quiet --release --example gmm_masks -- synthetic $(GMM_OUT)/synthetic
	$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/synthetic --min-agreement 100
	$(CARGO) run --quiet --release --example gmm_masks -- synthetic-grey $(GMM_OUT)/synthetic_grey
	$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/synthetic_grey --min-agreement 100
	$(CARGO) run --quiet --release --example gmm_masks -- synthetic $(GMM_OUT)/synthetic_sg --stauffer-grimson
	$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/synthetic_sg --min-agreement 100
	@if [ -d $(WAVING_TREES) ]; then \
		$(CARGO) run --quiet --release --example gmm_masks -- wallflower $(WAVING_TREES) $(GMM_OUT)/waving_trees && \
		$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/waving_trees --min-agreement 100; \
	else echo "SKIPPED: $(WAVING_TREES) is absent"; fi

# Stone Soup (PyPI) as the reference for track::pdaf: its PDA hypothesiser and updater, and an
# IMM built from its pieces, on the measurement sequences of the real outdoor following log
# and a segway_park log; every step must agree to 1e-9 (tools/stonesoup_pdaf_agreement.py).
VENV_SS := target/py-venv-stonesoup
PDAF_OUT := target/pdaf-agreement
REAL_FOLLOWING := ../shared/real/laser/person_following_outdoor_1/person_following_outdoor_1.mcap

$(VENV_SS)/ok:
	$(PYTHON) -m venv $(VENV_SS)
	$(VENV_SS)/bin/pip install --quiet --disable-pip-version-check stonesoup==1.9.1 numpy==2.4.6 scipy==1.17.1
	touch $@

stonesoup-agreement: $(VENV_SS)/ok release
	./target/release/peopletrack synth --if-absent datasets/segway_park/scenario.toml
	rm -rf $(PDAF_OUT)
	$(CARGO) run --quiet --release --example pdaf_agreement -- $(PDAF_OUT) --real $(REAL_FOLLOWING) --synthetic datasets/segway_park/segway_park_00.mcap
	$(VENV_SS)/bin/python tools/stonesoup_pdaf_agreement.py $(PDAF_OUT) --tol 1e-9

bench-gmm: $(VENV)/opencv-ok
	$(CARGO) bench --bench gmm -- --noplot
	$(VENV)/bin/python tools/bench_opencv_mog2.py target/bench-data/opencv_mog2.json
	$(VENV)/bin/python tools/bench_opencv_mog2.py --compare target/criterion target/bench-data/opencv_mog2.json

clean:
	$(CARGO) clean
	rm -rf out

# Fuzzing (issue 19): cargo-fuzz on the nightly toolchain; never needed by eval or test.
# `make fuzz` builds seed corpora (prefixes and small rewrites of the real laser logs and a
# synthetic log, their schemas and payloads, the pipeline files) and runs each target for
# FUZZ_RUNS executions (one target: FUZZ_TARGETS=cdr_decode). Without sanitizer (safe Rust;
# libFuzzer still catches panics, aborts, stack overflows, timeouts and RSS over the limit),
# with debug assertions and overflow checks on. Crashes land in fuzz/artifacts/<target>/.
.PHONY: fuzz fuzz-install fuzz-seeds
FUZZ_RUNS ?= 10000000
FUZZ_TARGETS ?= mcap_reader ros2msg_schema cdr_decode protobuf_decode pipeline_file
FUZZ_SEEDS := fuzz/seeds
FUZZ_LOGS := $(wildcard ../shared/real/laser/*/*.mcap) $(firstword $(wildcard datasets/home_tour/*.mcap))
FUZZ_FLAGS := -s none -a
FUZZ_LIBFUZZER := -rss_limit_mb=1024 -timeout=10 -max_len=65536 -print_final_stats=1

fuzz-install:
	@rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
	@cargo +nightly fuzz --version >/dev/null 2>&1 || cargo +nightly install cargo-fuzz --locked

fuzz-seeds:
	rm -rf $(FUZZ_SEEDS)
	$(CARGO) run --quiet --example fuzz_seeds -- $(FUZZ_SEEDS) $(FUZZ_LOGS)
	mkdir -p $(FUZZ_SEEDS)/pipeline_file
	cp pipelines/*.toml tests/fixtures/*.toml $(FUZZ_SEEDS)/pipeline_file/

fuzz: fuzz-install fuzz-seeds
	cargo +nightly fuzz build $(FUZZ_FLAGS)
	@for t in $(FUZZ_TARGETS); do \
		mkdir -p fuzz/corpus/$$t; \
		echo "== $$t: $(FUZZ_RUNS) runs"; \
		cargo +nightly fuzz run $(FUZZ_FLAGS) $$t fuzz/corpus/$$t $(FUZZ_SEEDS)/$$t -- \
			-runs=$(FUZZ_RUNS) $(FUZZ_LIBFUZZER) || exit 1; \
	done
