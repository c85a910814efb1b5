"""Time Python mcap-ros2-support reading and fully decoding every message of the same logs the
Rust benchmark reads (best of 3 runs), and decoding one topic alone (no output) for the rows
that `peopletrack cat --topic T` is compared with. Writes {name: {seconds, messages,
payload_bytes, limit_seconds}}; the one-topic rows are named `cat:LOG:TOPIC`.

`limit_seconds` is Python's own physical limit on the same file: the file read, every chunk
decompressed (the `zstandard` / `lz4` modules mcap itself uses) and each message payload
copied once, with no ordering, no index and no decoding (best of 3) -- the floor under any
Python reader, to set beside `NAME_limit` of the Rust benchmark."""
import json
import os
import struct
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


def _copy_messages(records, start, end):
    n = 0
    at = start
    while at + 9 <= end:
        op, length = records[at], struct.unpack_from("<Q", records, at + 1)[0]
        if op == 0x05:
            bytes(records[at + 9 + 22 : at + 9 + length])  # one copy of the payload
            n += 1
        at += 9 + length
    return n


def decompress_and_copy(path):
    """The file read, every chunk decompressed, every payload copied once; the message count."""
    import lz4.frame
    import zstandard

    data = memoryview(open(path, "rb").read())
    zstd = zstandard.ZstdDecompressor()
    n, at = 0, 8
    while at + 9 <= len(data):
        op, length = data[at], struct.unpack_from("<Q", data, at + 1)[0]
        body = at + 9
        if op == 0x05:
            n += _copy_messages(data, at, at + 9 + length)
        elif op == 0x06:
            size = struct.unpack_from("<Q", data, body + 16)[0]
            clen = struct.unpack_from("<I", data, body + 28)[0]
            compression = bytes(data[body + 32 : body + 32 + clen])
            rlen = struct.unpack_from("<Q", data, body + 32 + clen)[0]
            records = data[body + 40 + clen : body + 40 + clen + rlen]
            if compression == b"zstd":
                chunk = zstd.decompress(records, max_output_size=size)
            elif compression == b"lz4":
                chunk = lz4.frame.decompress(records)
            else:
                chunk = records
            n += _copy_messages(memoryview(chunk), 0, len(chunk))
        elif op in (0x0F, 0x02):
            break
        at += 9 + length
    return n


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
        limit = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            n_limit = decompress_and_copy(path)
            limit = min(limit, time.perf_counter() - t0)
        assert n_limit == n, f"{name}: the limit walk found {n_limit} messages, the reader {n}"
        results[name] = {
            "seconds": best,
            "messages": n,
            "payload_bytes": payload,
            "file_bytes": os.path.getsize(path),
            "limit_seconds": limit,
        }
        print(f"python {name}: {best:.3f} s, {n} messages; decompression + copy alone {limit:.3f} s")
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
