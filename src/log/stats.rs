//! Per-topic statistics of a session from one pass over its messages: counts, rates, gaps,
//! whether each channel decodes, and optionally the offset between header stamps and log time
//! (which needs every message decoded). Shared by `inspect` and the `dataset_quality` pipeline.

use std::collections::BTreeMap;

use serde::Serialize;

use super::decode::{Decoder, Decoders};
use super::error::LogError;
use super::reader::{ChannelInfo, SessionLog};
use super::sync::header_stamp;
use crate::time::Nanos;

/// Facts about one topic.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct TopicStats {
    pub topic: String,
    pub schema: String,
    pub schema_encoding: String,
    pub message_encoding: String,
    pub count: u64,
    pub first: Option<Nanos>,
    pub last: Option<Nanos>,
    /// Messages per second over the topic's own span: (n − 1) / span.
    pub rate_hz: f64,
    pub median_period_s: f64,
    pub max_gap_s: f64,
    /// Gaps longer than twice the median period (drops, or bursty delivery).
    pub long_gaps: u64,
    /// `ok`, or why the channel cannot be decoded.
    pub decoder: String,
    /// Header stamp − log time (s): min, median, max over messages that carry a stamp.
    pub stamp_offset_s: Option<(f64, f64, f64)>,
    /// Messages that failed to decode (counted, not fatal).
    pub decode_failures: u64,
    /// Message counts in consecutive bins of `bin_s` seconds from the session start.
    pub per_bin: Vec<u32>,
}

/// What to compute.
#[derive(Debug, Clone, Copy)]
pub struct StatsOptions {
    /// Decode every message to measure stamp offsets (otherwise only the first per channel).
    pub stamp_offsets: bool,
    /// Bin width for `per_bin` (0 disables binning).
    pub bin_s: f64,
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// One pass over every message of the log.
pub fn topic_stats(log: &SessionLog, opts: StatsOptions) -> Result<Vec<TopicStats>, LogError> {
    let s = log.summary();
    let start = s.statistics.as_ref().map(|st| st.start);
    let mut times: BTreeMap<u16, Vec<Nanos>> = BTreeMap::new();
    let mut offsets: BTreeMap<u16, Vec<f64>> = BTreeMap::new();
    let mut failures: BTreeMap<u16, u64> = BTreeMap::new();
    let mut status: BTreeMap<u16, String> = BTreeMap::new();
    let mut channels: BTreeMap<u16, std::sync::Arc<ChannelInfo>> = s.channels.clone();
    let mut decoders = Decoders::new();
    let mut first_time: Option<Nanos> = start;
    for m in log.messages()? {
        let m = m?;
        let id = m.channel.id;
        first_time.get_or_insert(m.log_time);
        times.entry(id).or_default().push(m.log_time);
        channels.entry(id).or_insert_with(|| m.channel.clone());
        let first_of_channel = !status.contains_key(&id);
        if first_of_channel || opts.stamp_offsets {
            match decoders.value(log, &m) {
                Ok(v) => {
                    status.entry(id).or_insert_with(|| "ok".to_string());
                    if let Some(stamp) = header_stamp(&v) {
                        offsets
                            .entry(id)
                            .or_default()
                            .push(stamp.signed_sub(m.log_time) as f64 * 1e-9);
                    }
                }
                Err(e) => {
                    status.entry(id).or_insert_with(|| e.kind.to_string());
                    *failures.entry(id).or_insert(0) += 1;
                }
            }
        }
    }
    let origin = first_time.unwrap_or_default();
    let mut out = Vec::new();
    for (id, ch) in &channels {
        let t = times.get(id).map(Vec::as_slice).unwrap_or(&[]);
        let mut periods: Vec<f64> = t
            .windows(2)
            .map(|w| (w[1].0 - w[0].0) as f64 * 1e-9)
            .collect();
        let max_gap = periods.iter().copied().fold(0.0, f64::max);
        let med = median(&mut periods);
        let long_gaps = periods.iter().filter(|p| **p > 2.0 * med).count() as u64;
        let span = match (t.first(), t.last()) {
            (Some(a), Some(b)) => (b.0 - a.0) as f64 * 1e-9,
            _ => 0.0,
        };
        let decoder = match status.get(id) {
            Some(s) => s.clone(),
            None => match Decoder::for_channel(ch) {
                Ok(_) => "ok (no messages)".to_string(),
                Err(e) => e.to_string(),
            },
        };
        let stamp_offset_s = offsets.get_mut(id).filter(|o| !o.is_empty()).map(|o| {
            let m = median(o); // sorts
            (o[0], m, o[o.len() - 1])
        });
        let per_bin = if opts.bin_s > 0.0 {
            let mut bins: Vec<u32> = Vec::new();
            for x in t {
                let k = ((x.0.saturating_sub(origin.0)) as f64 * 1e-9 / opts.bin_s) as usize;
                if bins.len() <= k {
                    bins.resize(k + 1, 0);
                }
                bins[k] += 1;
            }
            bins
        } else {
            Vec::new()
        };
        out.push(TopicStats {
            topic: ch.topic.clone(),
            schema: ch.schema_name().to_string(),
            schema_encoding: ch
                .schema
                .as_ref()
                .map_or(String::new(), |x| x.encoding.clone()),
            message_encoding: ch.message_encoding.clone(),
            count: t.len() as u64,
            first: t.first().copied(),
            last: t.last().copied(),
            rate_hz: if span > 0.0 {
                (t.len() - 1) as f64 / span
            } else {
                0.0
            },
            median_period_s: med,
            max_gap_s: max_gap,
            long_gaps,
            decoder,
            stamp_offset_s,
            decode_failures: failures.get(id).copied().unwrap_or(0),
            per_bin,
        });
    }
    out.sort_by(|a, b| a.topic.cmp(&b.topic));
    Ok(out)
}
