"""Put criterion's mean times beside Python's for the same files and print the ratios."""
import json
import os
import sys


def main(criterion_dir, python_json):
    py = json.load(open(python_json))
    print(f"{'log':40} {'messages':>9} {'MB':>8} {'rust s':>9} {'python s':>9} {'rust MB/s':>10} {'rust msg/s':>11} {'speed-up':>9}")
    for name, p in py.items():
        est = os.path.join(criterion_dir, "read_decode", name, "new", "estimates.json")
        if not os.path.exists(est):
            continue
        rust_s = json.load(open(est))["mean"]["point_estimate"] * 1e-9
        mb = p["payload_bytes"] / 1e6
        print(
            f"{name:40} {p['messages']:>9} {mb:>8.1f} {rust_s:>9.4f} {p['seconds']:>9.3f} "
            f"{mb / rust_s:>10.1f} {p['messages'] / rust_s:>11.0f} {p['seconds'] / rust_s:>8.1f}x"
        )


if __name__ == "__main__":
    main(*sys.argv[1:3])
