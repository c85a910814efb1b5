# peopletrack — the README's commands. `make help` lists the targets.
CARGO ?= cargo
PYTHON ?= python3
VENV := target/py-venv

.PHONY: help eval test bench interop clean opencv-agreement bench-gmm

help:
	@echo "make eval      build (release), run every pipeline, write out/ and out/REPORT.md"
	@echo "make test      build and run every test (the CI command)"
	@echo "make bench     criterion benchmarks + the same reads in Python mcap-ros2-support, with ratios"
	@echo "make interop   check that Python mcap-ros2-support opens what we write (throwaway venv)"
	@echo "make opencv-agreement  pixel agreement of vision::gmm masks with OpenCV MOG2 (throwaway venv)"
	@echo "make bench-gmm         adaptive GMM frames/s beside OpenCV MOG2 on the same frames, with ratios"
	@echo "make clean     remove build outputs and out/"

eval:
	$(CARGO) build --release --locked
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

bench: $(VENV)/ok
	$(CARGO) bench --bench read_decode -- --noplot
	$(VENV)/bin/python tools/bench_python_read.py target/bench-data/python_read.json
	$(VENV)/bin/python tools/bench_compare.py target/criterion target/bench-data/python_read.json

# OpenCV's MOG2 as the reference for vision::gmm, in the same throwaway venv (own stamp).
$(VENV)/opencv-ok: $(VENV)/ok
	$(VENV)/bin/pip install --quiet --disable-pip-version-check opencv-python-headless==4.12.0.88 numpy==2.2.6
	touch $@

GMM_OUT := target/gmm-agreement
WAVING_TREES := ../shared/real/wallflower_waving_trees/WavingTrees

opencv-agreement: $(VENV)/opencv-ok
	$(CARGO) run --quiet --release --example gmm_masks -- synthetic $(GMM_OUT)/synthetic
	$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/synthetic
	$(CARGO) run --quiet --release --example gmm_masks -- synthetic-grey $(GMM_OUT)/synthetic_grey
	$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/synthetic_grey
	$(CARGO) run --quiet --release --example gmm_masks -- synthetic $(GMM_OUT)/synthetic_sg --stauffer-grimson
	$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/synthetic_sg
	@if [ -d $(WAVING_TREES) ]; then \
		$(CARGO) run --quiet --release --example gmm_masks -- wallflower $(WAVING_TREES) $(GMM_OUT)/waving_trees && \
		$(VENV)/bin/python tools/opencv_mog2_agreement.py $(GMM_OUT)/waving_trees; \
	else echo "SKIPPED: $(WAVING_TREES) is absent"; fi

bench-gmm: $(VENV)/opencv-ok
	$(CARGO) bench --bench gmm -- --noplot
	$(VENV)/bin/python tools/bench_opencv_mog2.py target/bench-data/opencv_mog2.json
	$(VENV)/bin/python tools/bench_opencv_mog2.py --compare target/criterion target/bench-data/opencv_mog2.json

clean:
	$(CARGO) clean
	rm -rf out
