#!/bin/bash
# Scaling of a Slurm array (issue 34, docs/cluster.md): 10, 100 and 1,000 synthetic sessions of
# tools/scale/scenario.toml through an 8-way array + afterok aggregate on the cluster SLURM_CONF
# names. Prints sessions, wall time (submit to empty queue), the aggregate's own time, the
# aggregate's peak memory (the same aggregate rerun under /usr/bin/time) and the slowest shard.
# Usage: SLURM_CONF=... tools/scale/run.sh WORKDIR   (run from the project root, after make release)
set -euo pipefail
work=${1:?usage: tools/scale/run.sh WORKDIR}
bin=$PWD/target/release/peopletrack
mkdir -p "$work"
cp tools/scale/scenario.toml "$work/scenario.toml"
for p in s10 s100 quick; do "$bin" synth "$work/scenario.toml" --profile "$p" --out "$work/$p" >/dev/null; done
echo "sessions,wall_s,aggregate_s,aggregate_peak_rss_mib,shard_max_s,state"
for p in s10 s100 quick; do
  n=$(ls "$work/$p"/*.mcap | wc -l); out="$work/out_$p"; rm -rf "$out"
  t0=$(date +%s.%N)
  res=$("$bin" submit --slurm pipelines/dataset_quality.toml --shards 8 --mem 100M --out "$out" --sessions "$work/$p/*.mcap")
  agg=$(echo "$res" | sed -n 's/.*aggregate job \([0-9]*\).*/\1/p')
  while squeue -h | grep -q .; do sleep 0.2; done
  t1=$(date +%s.%N)
  state=$(scontrol show job "$agg" | grep -o "JobState=[A-Z]*" | cut -d= -f2)
  aggs=$(grep -o "in [0-9.]* s" "$out/dataset_quality/slurm/aggregate.log" | awk '{print $2}')
  shardmax=$(grep -ho "in [0-9.]* s" "$out"/dataset_quality/slurm/shard-*.log | awk '{print $2}' | sort -n | tail -1)
  /usr/bin/time -f "%M" -o "$work/rss" "$bin" run pipelines/dataset_quality.toml --out "$out" \
    --sessions "$work/$p/*.mcap" --aggregate-only --expect-shards 8 >/dev/null 2>&1
  rss=$(tail -1 "$work/rss")
  echo "$n,$(echo "$t1 - $t0" | bc),$aggs,$((rss / 1024)),$shardmax,$state"
done
