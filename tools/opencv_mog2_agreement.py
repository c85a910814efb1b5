"""Run OpenCV's BackgroundSubtractorMOG2 on the frames `examples/gmm_masks.rs` wrote, with
the same parameters, and print per-frame and overall pixel agreement with our masks.

Usage: python tools/opencv_mog2_agreement.py DIR [--min-agreement PCT]

DIR holds frames.bin, masks.bin, meta.json (and truth.bin when meta names an eval_frame).
Exit status 1 when the overall agreement is below --min-agreement (default 99.5 %).
"""
import argparse
import json
import os
import sys

import cv2
import numpy as np


def mog2(params):
    m = cv2.createBackgroundSubtractorMOG2(
        history=params["history"],
        varThreshold=params["var_threshold"],
        detectShadows=params["detect_shadows"],
    )
    m.setNMixtures(params["n_mixtures"])
    m.setBackgroundRatio(params["background_ratio"])
    m.setVarThresholdGen(params["var_threshold_gen"])
    m.setVarInit(params["var_init"])
    m.setVarMin(params["var_min"])
    m.setVarMax(params["var_max"])
    m.setComplexityReductionThreshold(params["complexity_reduction"])
    m.setShadowThreshold(params["shadow_threshold"])
    m.setShadowValue(params["shadow_value"])
    return m


def f_measure(mask, truth, shadow_fg):
    fg = (mask == 255) | ((mask != 0) & (mask != 255) & shadow_fg)
    gt = truth > 127
    tp = int(np.sum(fg & gt))
    fp = int(np.sum(fg & ~gt))
    fn = int(np.sum(~fg & gt))
    return 2 * tp / max(2 * tp + fp + fn, 1), tp, fp, fn


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--min-agreement", type=float, default=99.5)
    ap.add_argument("--show-frames", type=int, default=12, help="per-frame lines to print (worst first)")
    a = ap.parse_args()
    meta = json.load(open(os.path.join(a.dir, "meta.json")))
    n, h, w, c = meta["frames"], meta["height"], meta["width"], meta["channels"]
    frames = np.fromfile(os.path.join(a.dir, "frames.bin"), dtype=np.uint8).reshape(n, h, w, c)
    ours = np.fromfile(os.path.join(a.dir, "masks.bin"), dtype=np.uint8).reshape(n, h, w)

    cv2.setNumThreads(1)
    m = mog2(meta["params"])
    theirs = np.empty_like(ours)
    for i in range(n):
        theirs[i] = m.apply(np.ascontiguousarray(frames[i]))

    equal = (ours == theirs).reshape(n, -1).mean(axis=1) * 100.0
    overall = float((ours == theirs).mean() * 100.0)
    print(f"{meta['name']}: {n} frames {w}x{h}x{c}, OpenCV {cv2.__version__}")
    order = np.argsort(equal, kind="stable")
    shown = sorted(order[: a.show_frames])
    print("  per-frame agreement (the worst frames, in frame order):")
    for i in shown:
        d = ours[i] != theirs[i]
        kinds = {}
        for o, t in zip(ours[i][d].tolist(), theirs[i][d].tolist()):
            kinds[(o, t)] = kinds.get((o, t), 0) + 1
        detail = ", ".join(f"ours {o} / opencv {t}: {k}" for (o, t), k in sorted(kinds.items()))
        print(f"    frame {i:4d}: {equal[i]:8.4f} %  {detail}")
    print(f"  frames identical: {int(np.sum(equal == 100.0))} of {n}")
    print(f"  min frame agreement: {equal.min():.4f} %")
    print(f"  OVERALL pixel agreement: {overall:.4f} % ({int(np.sum(ours != theirs))} of {ours.size} pixels differ)")

    if "eval_frame" in meta:
        k = meta["eval_frame"]
        truth = np.fromfile(os.path.join(a.dir, "truth.bin"), dtype=np.uint8).reshape(h, w)
        for label, sfg in (("shadow as background", False), ("shadow as foreground", True)):
            fo, *co = f_measure(ours[k], truth, sfg)
            ft, *ct = f_measure(theirs[k], truth, sfg)
            print(f"  frame {k} F-measure ({label}): ours {fo:.4f} (TP FP FN {co}), OpenCV {ft:.4f} (TP FP FN {ct})")

    if overall < a.min_agreement:
        print(f"  BELOW the {a.min_agreement} % goal", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
