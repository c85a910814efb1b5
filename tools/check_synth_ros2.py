"""Open every synthesized session with Python mcap-ros2-support (an implementation that is not
ours), decode every ROS 2 message (and parse every JSON one), and compare the per-topic counts
with `peopletrack inspect --json` on the same file.

Usage: check_synth_ros2.py PEOPLETRACK_BINARY LOG.mcap...   (exit status 1 on any mismatch)
"""
import json
import subprocess
import sys
from collections import Counter

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def python_counts(path):
    counts = Counter()
    factory = DecoderFactory()
    decoders = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages(log_time_order=True):
            if channel.message_encoding == "json":
                json.loads(message.data)
            else:
                if channel.id not in decoders:
                    decoders[channel.id] = factory.decoder_for(channel.message_encoding, schema)
                decoders[channel.id](message.data)
            counts[channel.topic] += 1
    return counts


def main(binary, paths):
    bad = 0
    for path in paths:
        ours = json.loads(subprocess.check_output([binary, "inspect", "--json", path]))
        our_counts = {t["topic"]: t["count"] for t in ours["topics"]}
        theirs = python_counts(path)
        if dict(theirs) != our_counts:
            print(f"MISMATCH {path}: python {dict(theirs)} vs peopletrack {our_counts}")
            bad += 1
        else:
            print(f"OK {path}: {sum(theirs.values())} messages on {len(theirs)} topics decoded by mcap-ros2-support")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2:]))
