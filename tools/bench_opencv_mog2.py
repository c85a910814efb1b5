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
    """Print the issue's GMM rows: ours and OpenCV (same run) in frames/s, the ratio, and for
    2 threads each side's scaling over its own 1-thread figure (goal: ratio >= 2x per thread
    at 320x240 and 640x480, our scaling >= 1.8x on 2 cores)."""
    cv = json.load(open(opencv_json))
    print()
    print("| work | ours (frames/s) | OpenCV MOG2, same run | ratio | 2-thread scaling ours / OpenCV |")
    print("|---|---|---|---|---|")
    for name, c in clips().items():
        ours = {}
        for threads in (1, 2):
            key = f"{name}_t{threads}"
            est = os.path.join(criterion_dir, "gmm", f"adaptive_{key}", "new", "estimates.json")
            if os.path.exists(est):
                ours[threads] = 1e9 / json.load(open(est))["mean"]["point_estimate"]
        for threads in (1, 2):
            key = f"{name}_t{threads}"
            size = f"{c['width']}x{c['height']}"
            clip = size if name == size else f"{size} {name}"
            work = f"adaptive GMM {clip} RGB, {threads} thread{'s' if threads > 1 else ''}"
            if threads not in ours or key not in cv:
                print(f"| {work} | (missing) | | | |")
                continue
            fps, peer = ours[threads], cv[key]["fps"]
            scaling = ""
            if threads == 2 and 1 in ours and f"{name}_t1" in cv:
                scaling = f"{fps / ours[1]:.2f}x / {peer / cv[f'{name}_t1']['fps']:.2f}x"
            print(f"| {work} | {fps:,.0f} | {peer:,.0f} | **{fps / peer:.2f}x** | {scaling} |")
    load = os.getloadavg()[0]
    cores = os.cpu_count()
    note = "" if load < 0.5 * cores else " (busy: the ratios are indicative, the 2-thread scaling is not)"
    print(f"\nload average over the last minute: {load:.1f} on {cores} cores{note}")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--compare":
        compare(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 2:
        measure(sys.argv[1])
    else:
        sys.exit(__doc__)
