//! `peopletrack inspect LOG...`: what a log holds — topics, schemas and encodings, message
//! counts, rates, gaps, time span, the TF tree — and whether each channel decodes.
//!
//! [`analyze`] reads the log (the I/O), [`render_text`] is a pure function of its result.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use crate::log::decode::Decoder;
use crate::log::{Decoders, LogError, SessionLog, TfBuffer};
use crate::time::Nanos;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// MCAP session logs to describe.
    #[arg(required = true, value_name = "LOG")]
    pub logs: Vec<PathBuf>,
    /// Print one JSON document per log instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Per-topic facts.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct TopicReport {
    pub topic: String,
    pub schema: String,
    pub schema_encoding: String,
    pub message_encoding: String,
    pub count: u64,
    pub first_s: f64,
    pub last_s: f64,
    /// Messages per second over the topic's own span ((n − 1) / span).
    pub rate_hz: f64,
    pub median_period_s: f64,
    pub max_gap_s: f64,
    /// Gaps longer than twice the median period (drops, or bursty delivery).
    pub long_gaps: u64,
    /// `ok` or why the channel cannot be decoded.
    pub decoder: String,
}

/// One edge of the TF tree.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct TfEdge {
    pub parent: String,
    pub child: String,
    pub is_static: bool,
    pub samples: usize,
}

/// Everything `inspect` reports about one log.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Report {
    pub file: String,
    pub bytes: u64,
    pub profile: String,
    pub library: String,
    pub indexed_by_summary: bool,
    pub chunks: usize,
    pub compression: Vec<String>,
    pub messages: u64,
    pub start: String,
    pub end: String,
    pub duration_s: f64,
    pub topics: Vec<TopicReport>,
    pub tf_tree: Vec<TfEdge>,
    pub tf_tree_text: String,
    pub tf_skipped_invalid: u64,
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
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

/// Read the whole log once and gather the report.
pub fn analyze(log: &SessionLog) -> Result<Report, LogError> {
    let s = log.summary();
    let mut times: BTreeMap<u16, Vec<Nanos>> = BTreeMap::new();
    let mut decoders = Decoders::new();
    let mut decode_status: BTreeMap<u16, String> = BTreeMap::new();
    let mut channels = s.channels.clone();
    for m in log.messages()? {
        let m = m?;
        times.entry(m.channel.id).or_default().push(m.log_time);
        channels
            .entry(m.channel.id)
            .or_insert_with(|| m.channel.clone());
        // decode the first message of each channel to prove the channel is readable
        decode_status
            .entry(m.channel.id)
            .or_insert_with(|| match decoders.value(log, &m) {
                Ok(_) => "ok".to_string(),
                Err(e) => e.kind.to_string(),
            });
    }
    let mut topics = Vec::new();
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
        let decoder = match decode_status.get(id) {
            Some(s) => s.clone(),
            None => match Decoder::for_channel(ch) {
                Ok(_) => "ok (no messages)".to_string(),
                Err(e) => e.to_string(),
            },
        };
        topics.push(TopicReport {
            topic: ch.topic.clone(),
            schema: ch.schema_name().to_string(),
            schema_encoding: ch
                .schema
                .as_ref()
                .map_or(String::new(), |x| x.encoding.clone()),
            message_encoding: ch.message_encoding.clone(),
            count: t.len() as u64,
            first_s: t.first().map_or(f64::NAN, |x| x.as_secs_f64()),
            last_s: t.last().map_or(f64::NAN, |x| x.as_secs_f64()),
            rate_hz: if span > 0.0 {
                (t.len() - 1) as f64 / span
            } else {
                0.0
            },
            median_period_s: med,
            max_gap_s: max_gap,
            long_gaps,
            decoder,
        });
    }
    topics.sort_by(|a, b| a.topic.cmp(&b.topic));
    let start = times.values().filter_map(|t| t.first()).min().copied();
    let end = times.values().filter_map(|t| t.last()).max().copied();
    let tf = TfBuffer::from_log(log, 0.0)?;
    let mut compression: Vec<String> = s
        .chunks
        .iter()
        .map(|c| display_compression(&c.compression))
        .collect();
    compression.sort();
    compression.dedup();
    Ok(Report {
        file: log.path().display().to_string(),
        bytes: s.file_len,
        profile: s.profile.clone(),
        library: s.library.clone(),
        indexed_by_summary: s.from_summary_section,
        chunks: s.chunks.len(),
        compression,
        messages: times.values().map(|v| v.len() as u64).sum(),
        start: start.map_or(String::new(), |t| t.to_string()),
        end: end.map_or(String::new(), |t| t.to_string()),
        duration_s: match (start, end) {
            (Some(a), Some(b)) => (b.0 - a.0) as f64 * 1e-9,
            _ => 0.0,
        },
        topics,
        tf_tree: tf
            .tree()
            .into_iter()
            .map(|e| TfEdge {
                parent: e.parent,
                child: e.child,
                is_static: e.is_static,
                samples: e.samples,
            })
            .collect(),
        tf_tree_text: tf.render_tree(),
        tf_skipped_invalid: tf.stats().skipped_invalid,
        metadata: s
            .metadata
            .iter()
            .map(|m| (m.name.clone(), m.entries.clone()))
            .collect(),
    })
}

fn display_compression(c: &str) -> String {
    if c.is_empty() {
        "none".into()
    } else {
        c.into()
    }
}

/// The human-readable report.
pub fn render_text(r: &Report) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(o, "file:      {} ({} bytes)", r.file, r.bytes);
    let _ = writeln!(o, "profile:   {}  (library: {})", r.profile, r.library);
    let _ = writeln!(
        o,
        "index:     {} chunks ({}), {}",
        r.chunks,
        r.compression.join(", "),
        if r.indexed_by_summary {
            "from summary section"
        } else {
            "rebuilt by a linear pass (no summary section)"
        }
    );
    let _ = writeln!(o, "messages:  {}", r.messages);
    let _ = writeln!(
        o,
        "time:      {} .. {} s ({:.3} s)",
        r.start, r.end, r.duration_s
    );
    let _ = writeln!(o, "topics:");
    let w = r
        .topics
        .iter()
        .map(|t| t.topic.len())
        .max()
        .unwrap_or(5)
        .max(5);
    let ws = r
        .topics
        .iter()
        .map(|t| t.schema.len())
        .max()
        .unwrap_or(6)
        .max(6);
    let _ = writeln!(
        o,
        "  {:w$}  {:ws$}  {:>8}  {:>9}  {:>9}  {:>5}  encoding         decoder",
        "topic", "schema", "count", "rate Hz", "max gap s", ">2xmed"
    );
    for t in &r.topics {
        let _ = writeln!(
            o,
            "  {:w$}  {:ws$}  {:>8}  {:>9.3}  {:>9.3}  {:>5}  {:16} {}",
            t.topic,
            t.schema,
            t.count,
            t.rate_hz,
            t.max_gap_s,
            t.long_gaps,
            format!("{}/{}", t.message_encoding, t.schema_encoding),
            t.decoder
        );
    }
    if r.tf_tree_text.is_empty() {
        let _ = writeln!(o, "tf tree:   (no /tf or /tf_static)");
    } else {
        let _ = writeln!(o, "tf tree:");
        for line in r.tf_tree_text.lines() {
            let _ = writeln!(o, "  {line}");
        }
    }
    if r.tf_skipped_invalid > 0 {
        let _ = writeln!(o, "  ({} invalid transforms skipped)", r.tf_skipped_invalid);
    }
    for (name, entries) in &r.metadata {
        let _ = writeln!(o, "metadata {name}:");
        for (k, v) in entries {
            let v = if v.len() > 100 {
                format!(
                    "{}... ({} bytes)",
                    &v[..v.floor_char_boundary(100)],
                    v.len()
                )
            } else {
                v.clone()
            };
            let _ = writeln!(o, "  {k}: {}", v.replace('\n', "\\n"));
        }
    }
    o
}

pub fn run(args: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    for path in &args.logs {
        let log = SessionLog::open(path)?;
        let report = analyze(&log)?;
        if args.json {
            writeln!(out, "{}", serde_json::to_string_pretty(&report)?)?;
        } else {
            writeln!(out, "{}", render_text(&report))?;
        }
    }
    Ok(())
}
