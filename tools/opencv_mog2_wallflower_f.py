"""OpenCV MOG2's F-measure on Wallflower WavingTrees frame 247 (the reference row of the
`s003_zivkovic_background` pipeline's wallflower table; the pipeline itself never runs Python).

    target/py-venv/bin/python tools/opencv_mog2_wallflower_f.py ../shared/real/wallflower_waving_trees/WavingTrees

Needs opencv-python-headless (4.12.0.88, as installed by `make opencv-agreement`) and numpy.
"""
import sys

import cv2
import numpy as np

d = sys.argv[1]
m = cv2.createBackgroundSubtractorMOG2()  # defaults: history 500, varThreshold 16, shadows on
for i in range(248):
    mask = m.apply(cv2.imread(f"{d}/b{i:05d}.bmp", cv2.IMREAD_COLOR))
gt = cv2.imread(f"{d}/hand_segmented_00247.BMP", cv2.IMREAD_GRAYSCALE) > 127


def score(fg):
    tp = int((fg & gt).sum())
    fp = int((fg & ~gt).sum())
    fn = int((~fg & gt).sum())
    p, r = tp / (tp + fp), tp / (tp + fn)
    return 2 * p * r / (p + r), p, r, fp, fn


f, p, r, fp, fn = score(mask == 255)
f_sh = score(mask > 0)[0]
print(
    f"OpenCV {cv2.__version__} MOG2, WavingTrees frame 247: F = {f:.4f} "
    f"(shadow as foreground {f_sh:.4f}), precision {p:.4f}, recall {r:.4f}, FP {fp}, FN {fn}"
)
