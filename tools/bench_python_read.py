"""Time Python mcap-ros2-support reading and fully decoding every message of the same logs the
Rust benchmark reads (best of 3 runs), and decoding one topic alone (no output) for the rows
that `peopletrack cat --topic T` is compared with. Writes {name: {seconds, messages,
payload_bytes}}; the one-topic rows are named `cat:LOG:TOPIC`."""
import json
import os
import sys
import time

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILES = {
    name: os.path.join(ROOT, "..", "shared", "real", "laser", name, name + ".mcap")
    for name in ["general_tracking_moving_1", "person_following_outdoor_1", "demo_stationary_simple_environment"]
}
FILES["images_640x480"] = os.path.join(ROOT, "target", "bench-data", "images_640x480.mcap")


# `peopletrack cat LOG --topic T` is timed against Python decoding that topic alone.
CAT_ROWS = [("general_tracking_moving_1", "/scan"), ("general_tracking_moving_1", "/tf")]


def decode_all(path, topics=None):
    n = 0
    payload = 0
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _schema, _channel, message, _decoded in reader.iter_decoded_messages(topics=topics, log_time_order=True):
            n += 1
            payload += len(message.data)
    return n, payload


def main(out):
    results = {}
    for name, path in FILES.items():
        if not os.path.exists(path):
            print(f"skip {name}: {path} absent")
            continue
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            n, payload = decode_all(path)
            best = min(best, time.perf_counter() - t0)
        results[name] = {"seconds": best, "messages": n, "payload_bytes": payload, "file_bytes": os.path.getsize(path)}
        print(f"python {name}: {best:.3f} s, {n} messages")
    for name, topic in CAT_ROWS:
        path = FILES[name]
        if not os.path.exists(path):
            continue
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            n, payload = decode_all(path, [topic])
            best = min(best, time.perf_counter() - t0)
        results[f"cat:{name}:{topic}"] = {"seconds": best, "messages": n, "payload_bytes": payload, "path": path, "topic": topic}
        print(f"python {name} {topic} decode only: {best:.3f} s, {n} messages")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    json.dump(results, open(out, "w"), indent=2)


if __name__ == "__main__":
    main(sys.argv[1])
