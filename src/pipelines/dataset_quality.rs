//! `dataset_quality`: what every session holds and how healthy it is — duration, per-topic
//! counts, rates, gaps and drops, the TF tree, header-stamp vs log-time offsets, and ground-truth
//! statistics (people, speeds, visibility) where the session has them. Runs on any log,
//! synthetic or real; it is the first thing to look at before trusting an experiment's numbers.

use crate::names::sanitize;
use std::collections::BTreeMap;

use crate::progress::Progress;
use anyhow::Context;
use polars::prelude::*;
use serde::{Deserialize, Serialize};

use crate::groundtruth::{PEOPLE_TOPIC, PeopleFrame};
use crate::log::TfBuffer;
use crate::log::stats::{StatsOptions, topic_stats};
use crate::report::figure::{FigureKind, LinePlot, Series};
use crate::report::{Figure, Table};

use crate::report::columns::{concat as stack, f64s as col_f64, strs as col_str};
use crate::run::config::Invalid;
use crate::run::schemas::{TableDoc, table};
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

pub struct DatasetQuality;

/// Every per-session table and what a row of it is (`docs/schemas.md`).
const SESSION_TABLES: &[TableDoc] = &[
    table(
        "session",
        "The log as a whole (one row): duration, messages, topics, bytes, the writing library, \
         TF edges and invalid transforms, ground-truth frames, people, speeds and visibility.",
    ),
    table(
        "topics",
        "One topic: schema, encodings, count, rate, median period, gaps, header-stamp offsets \
         (null without header stamps), decode failures and the decoder used.",
    ),
    table(
        "rates",
        "One topic in one time bin: the message rate over the bin (Hz).",
    ),
    table(
        "tf",
        "One TF edge: parent, child, whether static, and how many samples it has.",
    ),
];

/// `[params]` of `pipelines/dataset_quality.toml`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Width of the bins of the rates-over-time figure (s).
    pub bin_s: f64,
    /// Decode every message to measure header-stamp offsets (slower on image logs).
    pub stamp_offsets: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            bin_s: 1.0,
            stamp_offsets: true,
        }
    }
}

fn topic(topics: &BTreeMap<String, String>, logical: &str, default: &str) -> String {
    topics
        .get(logical)
        .cloned()
        .unwrap_or_else(|| default.to_string())
}

impl Experiment for DatasetQuality {
    const KIND: &'static str = "dataset_quality";
    const VERSION: u32 = 1;
    const SESSION_TABLES: &'static [TableDoc] = SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        let mut out = Vec::new();
        if !(p.bin_s.is_finite() && p.bin_s > 0.0 && p.bin_s <= 3600.0) {
            out.push((
                "bin_s".into(),
                format!("{} is not in (0, 3600] seconds", p.bin_s),
            ));
        }
        out
    }

    fn topic_keys(_: &Params) -> Vec<String> {
        vec!["ground_truth".into()]
    }

    fn plan(_: &Params, topics: &BTreeMap<String, String>) -> Vec<Stage> {
        vec![
            Stage {
                name: "topic statistics".into(),
                requires: vec![],
                optional: vec![],
            },
            Stage {
                name: "tf tree".into(),
                requires: vec![],
                optional: vec!["/tf".into(), "/tf_static".into()],
            },
            Stage {
                name: "ground truth".into(),
                requires: vec![],
                optional: vec![topic(topics, "ground_truth", PEOPLE_TOPIC)],
            },
        ]
    }

    fn process(
        s: &Session,
        p: &Params,
        topics: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        bar.set_length(3);
        bar.set_message("topics");
        let log = &s.log;
        let stats = topic_stats(
            log,
            StatsOptions {
                stamp_offsets: p.stamp_offsets,
                bin_s: p.bin_s,
            },
        )?;
        bar.inc(1);
        let n = stats.len();
        let offset = |f: fn(&(f64, f64, f64)) -> f64| {
            stats
                .iter()
                .map(|t| t.stamp_offset_s.as_ref().map(f))
                .collect::<Vec<_>>()
        };
        let topics_df = df! {
            "topic" => stats.iter().map(|t| t.topic.clone()).collect::<Vec<_>>(),
            "schema" => stats.iter().map(|t| t.schema.clone()).collect::<Vec<_>>(),
            "encoding" => stats.iter().map(|t| format!("{}/{}", t.message_encoding, t.schema_encoding)).collect::<Vec<_>>(),
            "count" => stats.iter().map(|t| t.count as i64).collect::<Vec<_>>(),
            "rate_hz" => stats.iter().map(|t| t.rate_hz).collect::<Vec<_>>(),
            "median_period_s" => stats.iter().map(|t| t.median_period_s).collect::<Vec<_>>(),
            "max_gap_s" => stats.iter().map(|t| t.max_gap_s).collect::<Vec<_>>(),
            "gaps_over_2x_median" => stats.iter().map(|t| t.long_gaps as i64).collect::<Vec<_>>(),
            "stamp_offset_min_s" => offset(|o| o.0),
            "stamp_offset_median_s" => offset(|o| o.1),
            "stamp_offset_max_s" => offset(|o| o.2),
            "decode_failures" => stats.iter().map(|t| t.decode_failures as i64).collect::<Vec<_>>(),
            "decoder" => stats.iter().map(|t| t.decoder.clone()).collect::<Vec<_>>(),
        }?;
        let mut bins_topic = Vec::new();
        let mut bins_t = Vec::new();
        let mut bins_rate = Vec::new();
        for t in &stats {
            for (k, c) in t.per_bin.iter().enumerate() {
                bins_topic.push(t.topic.clone());
                bins_t.push(k as f64 * p.bin_s);
                bins_rate.push(f64::from(*c) / p.bin_s);
            }
        }
        let rates_df = df! { "topic" => bins_topic, "t_s" => bins_t, "rate_hz" => bins_rate }?;

        bar.set_message("tf");
        let tf = TfBuffer::from_log(log, 0.0)?;
        let tree = tf.tree();
        let tf_df = df! {
            "parent" => tree.iter().map(|e| e.parent.clone()).collect::<Vec<_>>(),
            "child" => tree.iter().map(|e| e.child.clone()).collect::<Vec<_>>(),
            "static" => tree.iter().map(|e| e.is_static).collect::<Vec<_>>(),
            "samples" => tree.iter().map(|e| e.samples as i64).collect::<Vec<_>>(),
        }?;
        bar.inc(1);

        bar.set_message("ground truth");
        let gt_topic = topic(topics, "ground_truth", PEOPLE_TOPIC);
        let (mut frames_gt, mut bad_gt) = (0i64, 0i64);
        let mut ids = std::collections::BTreeSet::new();
        let (mut speeds, mut visibilities) = (Vec::new(), Vec::new());
        if log.summary().channel(&gt_topic).is_some() {
            for m in log.messages_on(&[gt_topic.as_str()])? {
                let m = m?;
                let Ok(frame) = serde_json::from_slice::<PeopleFrame>(&m.data) else {
                    bad_gt += 1; // counted and reported, not fatal
                    continue;
                };
                frames_gt += 1;
                for person in &frame.people {
                    ids.insert(person.id);
                    speeds.push(person.vx.hypot(person.vy));
                    visibilities.extend(person.cameras.iter().map(|c| c.visibility));
                }
            }
        }
        bar.inc(1);
        let mean = |v: &[f64]| {
            if v.is_empty() {
                None
            } else {
                Some(v.iter().sum::<f64>() / v.len() as f64)
            }
        };
        let start = stats.iter().filter_map(|t| t.first).min();
        let end = stats.iter().filter_map(|t| t.last).max();
        let summary = log.summary();
        let session_df = df! {
            "dataset" => [s.info.dataset.clone()],
            "session" => [s.info.name.clone()],
            "duration_s" => [match (start, end) { (Some(a), Some(b)) => (b.0 - a.0) as f64 * 1e-9, _ => 0.0 }],
            "messages" => [stats.iter().map(|t| t.count as i64).sum::<i64>()],
            "topics" => [n as i64],
            "bytes" => [summary.file_len as i64],
            "library" => [summary.library.clone()],
            "tf_edges" => [tree.len() as i64],
            "tf_invalid" => [tf.stats().skipped_invalid as i64],
            "gt_frames" => [frames_gt],
            "gt_bad_frames" => [bad_gt],
            "gt_people" => [ids.len() as i64],
            "gt_mean_speed_mps" => [mean(&speeds)],
            "gt_max_speed_mps" => [speeds.iter().copied().reduce(f64::max)],
            "gt_mean_visibility" => [mean(&visibilities)],
        }?;
        Ok(SessionTables::from([
            ("session".to_string(), session_df),
            ("topics".to_string(), topics_df),
            ("rates".to_string(), rates_df),
            ("tf".to_string(), tf_df),
        ]))
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        let mut sessions = Vec::new();
        let mut topics = Vec::new();
        for (info, frames) in ctx.sessions {
            sessions.push(
                frames
                    .get("session")
                    .context("cached result lacks the session table")?
                    .clone(),
            );
            let t = frames
                .get("topics")
                .context("cached result lacks the topics table")?;
            let mut t = t.clone();
            t.insert_column(
                0,
                Column::new("session".into(), vec![info.name.clone(); t.height()]),
            )?;
            t.insert_column(
                0,
                Column::new("dataset".into(), vec![info.dataset.clone(); t.height()]),
            )?;
            topics.push(t);
        }
        let sessions_df = stack(sessions)?;
        let topics_df = stack(topics)?;
        let mut products = Products::default();
        let n_sessions = sessions_df.height();
        let total_s: f64 = col_f64(&sessions_df, "duration_s")?.iter().sum();
        let failures: i64 = topics_df
            .column("decode_failures")?
            .i64()?
            .iter()
            .flatten()
            .sum();
        products.summary.push(format!(
            "{n_sessions} sessions, {:.1} min of data, {} topics in all, {failures} messages that failed to decode.",
            total_s / 60.0,
            topics_df.height()
        ));
        products.tables.push(
            Table::new("sessions", "Sessions: duration, size, TF tree and ground-truth statistics", sessions_df)
                .with_precision("duration_s", 1)
                .with_precision("gt_mean_speed_mps", 2)
                .with_precision("gt_max_speed_mps", 2)
                .with_precision("gt_mean_visibility", 2)
                .with_note("No paper values: this table describes the data every other table is computed from."),
        );
        products.tables.push(
            Table::new("topics", "Topics: counts, rates, gaps and header-stamp offsets per session", topics_df)
                .with_precision("rate_hz", 2)
                .with_precision("median_period_s", 4)
                .with_precision("max_gap_s", 3)
                .with_precision("stamp_offset_min_s", 4)
                .with_precision("stamp_offset_median_s", 4)
                .with_precision("stamp_offset_max_s", 4)
                .with_note("gaps_over_2x_median counts gaps longer than twice the topic's median period (drops, or bursty delivery). Stamp offsets are header stamp minus log time."),
        );
        // one rates-over-time figure per dataset (its first session)
        let mut seen = std::collections::BTreeSet::new();
        for (info, frames) in ctx.sessions {
            if !seen.insert(info.dataset.clone()) {
                continue;
            }
            let Some(rates) = frames.get("rates") else {
                continue;
            };
            let names = col_str(rates, "topic")?;
            let (t, r) = (col_f64(rates, "t_s")?, col_f64(rates, "rate_hz")?);
            let mut by_topic: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
            for i in 0..names.len() {
                by_topic
                    .entry(names[i].clone())
                    .or_default()
                    .push((t[i] + p.bin_s / 2.0, r[i]));
            }
            let series = by_topic
                .into_iter()
                .enumerate()
                .map(|(k, (name, pts))| Series::line(name, pts, k + 1))
                .collect();
            products.figures.push(Figure::new(
                format!("rates_{}", sanitize(&info.dataset)),
                format!("Message rates over time: {}/{}", info.dataset, info.name),
                FigureKind::Lines(LinePlot {
                    x_label: "time since start (s)".into(),
                    y_label: format!("messages per second ({} s bins)", p.bin_s),
                    series,
                    ..Default::default()
                }),
            ));
        }
        Ok(products)
    }
}
