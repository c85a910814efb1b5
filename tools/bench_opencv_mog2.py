"""Time OpenCV's BackgroundSubtractorMOG2 (default parameters) on the frames `benches/gmm.rs`
wrote, on 1 and 2 threads, the same way: the model first sees the whole clip once, then each
timed apply() continues it. Writes {"WxH_tN": {"fps": .., "ms_per_frame": ..}}.

Usage:
  python tools/bench_opencv_mog2.py OUT.json
  python tools/bench_opencv_mog2.py --compare CRITERION_DIR OUT.json   (print the ratios)
"""
import json
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIZES = [(320, 240), (640, 480)]
CLIP = 64
PASSES = 5  # timed passes over the clip; the best pass is kept


def measure(out):
    import cv2
    import numpy as np

    results = {}
    for w, h in SIZES:
        path = os.path.join(ROOT, "target", "bench-data", f"gmm_frames_{w}x{h}.bin")
        frames = np.fromfile(path, dtype=np.uint8).reshape(CLIP, h, w, 3)
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
                best = min(best, (time.perf_counter() - t0) / CLIP)
            key = f"{w}x{h}_t{threads}"
            results[key] = {"fps": 1.0 / best, "ms_per_frame": best * 1e3}
            print(f"OpenCV {cv2.__version__} MOG2 {key}: {1.0 / best:8.1f} frames/s ({best * 1e3:.3f} ms/frame)")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    json.dump(results, open(out, "w"), indent=2)


def compare(criterion_dir, opencv_json):
    cv = json.load(open(opencv_json))
    print(f"{'size':>9} {'threads':>7} {'ours fps':>10} {'OpenCV fps':>11} {'ours/OpenCV':>12}")
    for w, h in SIZES:
        for threads in (1, 2):
            key = f"{w}x{h}_t{threads}"
            est = os.path.join(criterion_dir, "gmm", f"adaptive_{key}", "new", "estimates.json")
            if not os.path.exists(est) or key not in cv:
                print(f"{w}x{h:<5} {threads:>7}  (missing)")
                continue
            ours_fps = 1e9 / json.load(open(est))["mean"]["point_estimate"]
            print(f"{f'{w}x{h}':>9} {threads:>7} {ours_fps:>10.1f} {cv[key]['fps']:>11.1f} {ours_fps / cv[key]['fps']:>11.2f}x")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--compare":
        compare(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 2:
        measure(sys.argv[1])
    else:
        sys.exit(__doc__)
