"""Put criterion's mean times beside Python's for the same files and print the ratios.

Usage: bench_compare.py CRITERION_DIR PYTHON_JSON [PEOPLETRACK_BINARY]

Rows:
- read + decode every message (`read_decode/NAME`: typed fast paths where a channel has one,
  flat decoding of the other CDR types) beside Python mcap-ros2-support, with `NAME_dynamic` (value tree
  only) and the physical limit `NAME_limit` (file read + zstd/lz4 decompression + one copy of
  each payload): "limit %" is limit time / decode time (100 % = decoding is free); "py limit
  s" is the same limit measured in Python (its zstandard/lz4 modules, one copy per payload) and
  "ceiling" is Python's time over our limit: the largest ratio any reader of ours could show
  on that file (where Python's time is itself mostly decompression, the ceiling is low);
- with a binary: `peopletrack cat LOG --topic T` as a whole process, JSON to /dev/null (best of
  5), beside Python decoding that topic alone with no output.
"""
import json
import os
import subprocess
import sys
import time


def mean_s(criterion_dir, name):
    est = os.path.join(criterion_dir, "read_decode", name, "new", "estimates.json")
    if not os.path.exists(est):
        return None
    return json.load(open(est))["mean"]["point_estimate"] * 1e-9


def cat_seconds(binary, path, topic, runs=5):
    best = float("inf")
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run([binary, "cat", path, "--topic", topic], stdout=subprocess.DEVNULL, check=True)
        best = min(best, time.perf_counter() - t0)
    return best


def main(criterion_dir, python_json, binary=None):
    py = json.load(open(python_json))
    print("read + decode every message (ours: typed fast paths + flat CDR; peer: mcap-ros2-support)")
    print(
        f"{'log':36} {'messages':>9} {'MB':>7} {'ours s':>9} {'python s':>9} {'ratio':>8} "
        f"{'dynamic s':>10} {'limit s':>9} {'limit %':>8} {'ours MB/s':>10} {'py limit s':>11} {'ceiling':>8}"
    )
    for name, p in py.items():
        if name.startswith("cat:"):
            continue
        rust_s = mean_s(criterion_dir, name)
        if rust_s is None:
            continue
        dyn_s = mean_s(criterion_dir, name + "_dynamic")
        lim_s = mean_s(criterion_dir, name + "_limit")
        mb = p["payload_bytes"] / 1e6
        fmt = lambda x, w, d: f"{x:>{w}.{d}f}" if x is not None else f"{'-':>{w}}"
        pct = 100.0 * lim_s / rust_s if lim_s is not None else None
        py_lim = p.get("limit_seconds")
        ceiling = p["seconds"] / lim_s if lim_s else None
        print(
            f"{name:36} {p['messages']:>9} {mb:>7.1f} {rust_s:>9.4f} {p['seconds']:>9.3f} "
            f"{p['seconds'] / rust_s:>7.1f}x {fmt(dyn_s, 10, 4)} {fmt(lim_s, 9, 4)} "
            f"{fmt(pct, 7, 0)}% {mb / rust_s:>10.1f} {fmt(py_lim, 11, 3)} "
            + (f"{ceiling:>7.1f}x" if ceiling is not None else f"{'-':>8}")
        )
    cats = {k: v for k, v in py.items() if k.startswith("cat:")}
    if binary and cats:
        print()
        print("peopletrack cat --topic T, whole process, JSON to /dev/null (best of 5) vs Python decode only, no output")
        print(f"{'log':28} {'topic':8} {'messages':>9} {'ours s':>8} {'python s':>9} {'ratio':>7}")
        for key, p in cats.items():
            _, name, topic = key.split(":", 2)
            ours = cat_seconds(binary, p["path"], topic)
            print(f"{name:28} {topic:8} {p['messages']:>9} {ours:>8.3f} {p['seconds']:>9.3f} {p['seconds'] / ours:>6.1f}x")


if __name__ == "__main__":
    main(*sys.argv[1:4])
