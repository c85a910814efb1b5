"""Time OpenCV's BackgroundSubtractorMOG2 (default parameters) on the clips `benches/gmm.rs`
wrote (target/bench-data/gmm_clips.json), on 1 and 2 threads, the way the Rust benchmark
does: the model first sees the whole clip once, then each timed apply() continues it.
Writes {"CLIP_tN": {"fps": .., "ms_per_frame": ..}}.

Usage:
  python tools/bench_opencv_mog2.py OUT.json
  python tools/bench_opencv_mog2.py --compare CRITERION_DIR OUT.json   (print the ratios)
"""
import json
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "target", "bench-data")
PASSES = 5  # timed passes over the clip; the best pass is kept


def clips():
    return json.load(open(os.path.join(DATA, "gmm_clips.json")))


def measure(out):
    import cv2
    import numpy as np

    results = {}
    for name, c in clips().items():
        w, h, n = c["width"], c["height"], c["frames"]
        frames = np.fromfile(os.path.join(DATA, c["file"]), dtype=np.uint8).reshape(n, h, w, 3)
        frames = [np.ascontiguousarray(f) for f in frames]
        for threads in (1, 2):
            cv2.setNumThreads(threads)
            m = cv2.createBackgroundSubtractorMOG2()
            mask = np.empty((h, w), np.uint8)
            for f in frames:
                m.apply(f, mask)
            best = float("inf")
            for _ in range(PASSES):
                t0 = time.perf_counter()
                for f in frames:
                    m.apply(f, mask)
                best = min(best, (time.perf_counter() - t0) / n)
            key = f"{name}_t{threads}"
            results[key] = {"fps": 1.0 / best, "ms_per_frame": best * 1e3}
            print(f"OpenCV {cv2.__version__} MOG2 {key}: {1.0 / best:8.1f} frames/s ({best * 1e3:.3f} ms/frame)")
    json.dump(results, open(out, "w"), indent=2)


def compare(criterion_dir, opencv_json):
    cv = json.load(open(opencv_json))
    print(f"{'clip':>13} {'threads':>7} {'ours fps':>10} {'OpenCV fps':>11} {'ours/OpenCV':>12}")
    for name in clips():
        for threads in (1, 2):
            key = f"{name}_t{threads}"
            est = os.path.join(criterion_dir, "gmm", f"adaptive_{key}", "new", "estimates.json")
            if not os.path.exists(est) or key not in cv:
                print(f"{name:>13} {threads:>7}  (missing)")
                continue
            ours_fps = 1e9 / json.load(open(est))["mean"]["point_estimate"]
            print(f"{name:>13} {threads:>7} {ours_fps:>10.1f} {cv[key]['fps']:>11.1f} {ours_fps / cv[key]['fps']:>11.2f}x")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--compare":
        compare(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 2:
        measure(sys.argv[1])
    else:
        sys.exit(__doc__)
