"""Score the synthetic sequence of `benches/mot.rs` with py-motmetrics, check that its numbers
agree with ours, and print seconds and the speed ratio.

usage: bench_motmetrics.py DATA_DIR CRITERION_DIR [REPEATS]

DATA_DIR holds gt.txt, hyp.txt (MOTChallenge CSV) and ours.json, written by
`cargo bench --bench mot`; CRITERION_DIR is criterion's output (target/criterion). The timed
work is what `mot/clear_identity_from_csv` times: load both files, match every frame
(IoU >= 0.5), and compute the MOTChallenge metrics (CLEAR MOT and IDF1).
"""
import json
import os
import sys
import time

import motmetrics as mm

# motmetrics column -> (section, field) in ours.json
FIELDS = {
    "idf1": ("identity", "idf1"),
    "idp": ("identity", "idp"),
    "idr": ("identity", "idr"),
    "recall": ("clear", "recall"),
    "precision": ("clear", "precision"),
    "num_unique_objects": ("clear", "num_unique_objects"),
    "mostly_tracked": ("clear", "mostly_tracked"),
    "partially_tracked": ("clear", "partially_tracked"),
    "mostly_lost": ("clear", "mostly_lost"),
    "num_false_positives": ("clear", "num_false_positives"),
    "num_misses": ("clear", "num_misses"),
    "num_switches": ("clear", "num_switches"),
    "num_fragmentations": ("clear", "num_fragmentations"),
    "mota": ("clear", "mota"),
    "motp": ("clear", "motp"),
    "num_transfer": ("clear", "num_transfer"),
    "num_ascend": ("clear", "num_ascend"),
    "num_migrate": ("clear", "num_migrate"),
}


def score(data_dir):
    gt = mm.io.loadtxt(os.path.join(data_dir, "gt.txt"))
    hyp = mm.io.loadtxt(os.path.join(data_dir, "hyp.txt"))
    acc = mm.utils.compare_to_groundtruth(gt, hyp, "iou", distth=0.5)
    mh = mm.metrics.create()
    return mh.compute(acc, metrics=mm.metrics.motchallenge_metrics, return_dataframe=False)


def main(data_dir, criterion_dir, repeats=1):
    ours = json.load(open(os.path.join(data_dir, "ours.json")))
    seconds = []
    for _ in range(int(repeats)):
        t0 = time.perf_counter()
        theirs = score(data_dir)
        seconds.append(time.perf_counter() - t0)
    python_s = min(seconds)

    worst = 0.0
    for name, (section, field) in FIELDS.items():
        a, b = float(theirs[name]), float(ours["metrics"][section][field])
        worst = max(worst, abs(a - b))
        if abs(a - b) > 1e-12:
            print(f"MISMATCH {name}: py-motmetrics {a!r}, ours {b!r}")
    print(
        f"input: {ours['frames']} frames, {ours['gt_rows']} ground-truth boxes, "
        f"{ours['hyp_rows']} tracker boxes (target/bench-data/mot)"
    )
    print(
        f"metrics: MOTA {theirs['mota']:.6f}  MOTP {theirs['motp']:.6f}  IDF1 {theirs['idf1']:.6f}  "
        f"IDSW {theirs['num_switches']}  FM {theirs['num_fragmentations']}; "
        f"largest difference to ours over {len(FIELDS)} values: {worst:.2e}"
    )

    print(f"{'benchmark':38} {'rust s':>10} {'python s':>10} {'speed-up':>9}")
    notes = {
        "clear_identity_from_csv": "  (goal: 100x)",
        "clear_identity_from_csv_two_threads": "  (ours parses the two files on two threads)",
        "all_metrics_from_csv": "  (ours also computes HOTA)",
    }
    for bench in notes:
        est = os.path.join(criterion_dir, "mot", bench, "new", "estimates.json")
        if not os.path.exists(est):
            print(f"{bench:38} (no criterion estimate at {est})")
            continue
        rust_s = json.load(open(est))["mean"]["point_estimate"] * 1e-9
        note = notes[bench]
        print(f"{bench:38} {rust_s:>10.4f} {python_s:>10.3f} {python_s / rust_s:>8.1f}x{note}")
    print(f"py-motmetrics {mm.__version__}, best of {len(seconds)}: " + ", ".join(f"{s:.3f}" for s in seconds) + " s")


if __name__ == "__main__":
    main(*sys.argv[1:4])
