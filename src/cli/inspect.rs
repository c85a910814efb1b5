//! `peopletrack inspect LOG...`: what a log holds — topics, schemas and encodings, message
//! counts, rates, gaps, time span, the TF tree — and whether each channel decodes.
//!
//! [`analyze`] reads the log (the I/O), [`render_text`] is a pure function of its result.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use peopletrack::log::stats::{StatsOptions, TopicStats, topic_stats};
use peopletrack::log::{LogError, SessionLog, TfBuffer};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// MCAP session logs to describe.
    #[arg(required = true, value_name = "LOG")]
    pub logs: Vec<PathBuf>,
    /// Print one JSON document per log instead of text.
    #[arg(long)]
    pub json: bool,
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
    pub topics: Vec<TopicStats>,
    pub tf_tree: Vec<TfEdge>,
    pub tf_tree_text: String,
    pub tf_skipped_invalid: u64,
    /// Frames published on both /tf and /tf_static (the moving samples win).
    pub tf_static_and_dynamic: u64,
    /// Times a frame changed parent.
    pub tf_reparented: u64,
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// Whether corruption can be detected ([`peopletrack::log::CrcCoverage::describe`]).
    pub crc: String,
    /// Where the file's index disagreed with its data (the data was believed).
    pub warnings: Vec<String>,
}

/// Read the whole log once and gather the report.
pub fn analyze(log: &SessionLog) -> Result<Report, LogError> {
    let s = log.summary();
    let topics = topic_stats(
        log,
        StatsOptions {
            stamp_offsets: false,
            bin_s: 0.0,
        },
    )?;
    let start = topics.iter().filter_map(|t| t.first).min();
    let end = topics.iter().filter_map(|t| t.last).max();
    let tf = TfBuffer::from_log(log, 0.0)?;
    let crc = log.crc_coverage()?;
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
        messages: topics.iter().map(|t| t.count).sum(),
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
        tf_static_and_dynamic: tf.stats().static_and_dynamic,
        tf_reparented: tf.stats().reparented,
        metadata: s
            .metadata
            .iter()
            .map(|m| (m.name.clone(), m.entries.clone()))
            .collect(),
        crc: crc.describe(),
        warnings: s.warnings.clone(),
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
    let _ = writeln!(o, "crc:       {}", r.crc);
    for w in &r.warnings {
        let _ = writeln!(o, "warning:   {w}");
    }
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
    if r.tf_static_and_dynamic > 0 {
        let _ = writeln!(
            o,
            "  (warning: {} transforms for frames on both /tf and /tf_static; the moving samples win)",
            r.tf_static_and_dynamic
        );
    }
    if r.tf_reparented > 0 {
        let _ = writeln!(
            o,
            "  (warning: frames changed parent {} times; the newest parent wins)",
            r.tf_reparented
        );
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
