//! Known answers on real tracker output: TUD-Campus and TUD-Stadtmitte (MOTChallenge 2015
//! ground truth + one tracker's boxes, as shipped with py-motmetrics), IoU matching at 0.5.
//!
//! - CLEAR MOT and IDF1: every value of `../shared/real/motmetrics/expected_metrics.txt`
//!   (py-motmetrics 1.4.0's own test), per sequence and for the OVERALL row, to 1e-6.
//! - Transfers, ascends and migrations: py-motmetrics 1.4.0 run on the same files
//!   (`compare_to_groundtruth(gt, test, 'iou', distth=0.5)` + `compute_many(...,
//!   generate_overall=True)`, numpy 1.26.4, pandas 2.2.3, scipy 1.13.1).
//! - HOTA, DetA, AssA, LocA, DetRe, DetPr, AssRe, AssPr: TrackEval 1.3.0 (PyPI `trackeval`)
//!   `metrics.HOTA.eval_sequence` / `combine_sequences` fed the raw files (ids and frames as
//!   in the files, similarity from TrackEval's `_calculate_box_ious(..., 'xywh')`, no
//!   MOTChallenge preprocessing), means over α printed to 12 decimals; compared to 1e-9.

use crate::common;

use std::path::Path;

use peopletrack::eval::mot::{
    EventKind, GeometryKind, MatchRule, Metrics, Observation, evaluate, parse_motchallenge,
};

const SEQUENCES: [&str; 2] = ["TUD-Campus", "TUD-Stadtmitte"];

fn load(path: &Path) -> Vec<Observation> {
    let text = std::fs::read_to_string(path).expect("readable");
    parse_motchallenge(&text, path, GeometryKind::Box).expect("parses")
}

fn score(dir: &Path, name: &str) -> (Metrics, Vec<peopletrack::eval::mot::Event>) {
    let gt = load(&dir.join(name).join("gt.txt"));
    let hyp = load(&dir.join(name).join("test.txt"));
    let e = evaluate(&gt, &hyp, MatchRule::Iou { min_iou: 0.5 }).expect("scores");
    (e.metrics, e.events)
}

/// One named value of ours, by motmetrics' column name.
fn value(m: &Metrics, column: &str) -> Option<f64> {
    let c = &m.clear;
    let i = &m.identity;
    Some(match column {
        "idf1" => i.idf1,
        "idp" => i.idp,
        "idr" => i.idr,
        "recall" => c.recall,
        "precision" => c.precision,
        "num_unique_objects" => c.num_unique_objects as f64,
        "mostly_tracked" => c.mostly_tracked as f64,
        "partially_tracked" => c.partially_tracked as f64,
        "mostly_lost" => c.mostly_lost as f64,
        "num_false_positives" => c.num_false_positives as f64,
        "num_misses" => c.num_misses as f64,
        "num_switches" => c.num_switches as f64,
        "num_fragmentations" => c.num_fragmentations as f64,
        "mota" => c.mota,
        "motp" => c.motp,
        _ => return None,
    })
}

/// (column names, rows of (name, values)) from expected_metrics.txt.
fn expected(path: &Path) -> (Vec<String>, Vec<(String, Vec<f64>)>) {
    let text = std::fs::read_to_string(path).expect("readable");
    let mut columns = Vec::new();
    let mut rows = Vec::new();
    for line in text.lines() {
        if let Some(c) = line.strip_prefix("# columns:") {
            columns = c.split_whitespace().map(String::from).collect();
        } else if !line.starts_with('#') && !line.trim().is_empty() {
            let mut f = line.split_whitespace();
            let name = f.next().expect("name").to_string();
            let values: Vec<f64> = f.map(|v| v.parse().expect("number")).collect();
            rows.push((name, values));
        }
    }
    (columns, rows)
}

#[test]
fn clear_mot_and_idf1_match_py_motmetrics() {
    let Some(dir) = common::real("motmetrics") else {
        return;
    };
    let (columns, rows) = expected(&dir.join("expected_metrics.txt"));
    assert_eq!(columns.len(), 15, "{columns:?}");
    let per_seq: Vec<Metrics> = SEQUENCES.iter().map(|s| score(&dir, s).0).collect();
    let overall = Metrics::overall(&per_seq);
    let mut checked = 0;
    for (name, values) in &rows {
        let ours = match name.as_str() {
            "OVERALL" => &overall,
            n => {
                &per_seq[SEQUENCES
                    .iter()
                    .position(|s| *s == n)
                    .expect("known sequence")]
            }
        };
        assert_eq!(values.len(), columns.len(), "row {name}");
        for (col, want) in columns.iter().zip(values) {
            let got = value(ours, col).unwrap_or_else(|| panic!("unknown column {col}"));
            assert!(
                (got - want).abs() <= 1e-6,
                "{name} {col}: ours {got}, py-motmetrics {want}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 45, "3 rows × 15 values");
}

#[test]
fn transfers_ascends_migrations_match_py_motmetrics() {
    let Some(dir) = common::real("motmetrics") else {
        return;
    };
    let per_seq: Vec<Metrics> = SEQUENCES.iter().map(|s| score(&dir, s).0).collect();
    let t = |m: &Metrics| {
        (
            m.clear.num_transfer,
            m.clear.num_ascend,
            m.clear.num_migrate,
        )
    };
    assert_eq!(t(&per_seq[0]), (2, 7, 2));
    assert_eq!(t(&per_seq[1]), (5, 4, 2));
    assert_eq!(t(&Metrics::overall(&per_seq)), (7, 11, 4));
}

#[test]
fn hota_matches_trackeval() {
    let Some(dir) = common::real("motmetrics") else {
        return;
    };
    // HOTA DetA AssA LocA DetRe DetPr AssRe AssPr
    let trackeval: [(&str, [f64; 8]); 3] = [
        (
            "TUD-Campus",
            [
                0.391397437845,
                0.418047030143,
                0.369120681208,
                0.770052227022,
                0.441577481308,
                0.714082503556,
                0.383224913943,
                0.754049776587,
            ],
        ),
        (
            "TUD-Stadtmitte",
            [
                0.397849016993,
                0.392267572369,
                0.408840751811,
                0.737521177178,
                0.413130577308,
                0.637622092615,
                0.449219009263,
                0.631203323676,
            ],
        ),
        (
            "COMBINED",
            [
                0.399957091288,
                0.397683291242,
                0.412449529845,
                0.732480258066,
                0.419871460830,
                0.655103257629,
                0.450664647512,
                0.692210501451,
            ],
        ),
    ];
    let per_seq: Vec<Metrics> = SEQUENCES.iter().map(|s| score(&dir, s).0).collect();
    let combined = Metrics::overall(&per_seq);
    for (k, (name, want)) in trackeval.iter().enumerate() {
        let h = if k < 2 {
            &per_seq[k].hota
        } else {
            &combined.hota
        };
        let got = [
            h.hota, h.det_a, h.ass_a, h.loc_a, h.det_re, h.det_pr, h.ass_re, h.ass_pr,
        ];
        for (field, (g, w)) in [
            "HOTA", "DetA", "AssA", "LocA", "DetRe", "DetPr", "AssRe", "AssPr",
        ]
        .iter()
        .zip(got.iter().zip(want))
        {
            assert!(
                (g - w).abs() <= 1e-9,
                "{name} {field}: ours {g}, TrackEval {w}"
            );
        }
    }
}

#[test]
fn events_add_up_to_the_counts() {
    let Some(dir) = common::real("motmetrics") else {
        return;
    };
    let (m, events) = score(&dir, "TUD-Campus");
    let n = |k: EventKind| events.iter().filter(|e| e.kind == k).count() as u64;
    assert_eq!(n(EventKind::Match), m.clear.num_matches);
    assert_eq!(n(EventKind::Switch), m.clear.num_switches);
    assert_eq!(n(EventKind::Miss), m.clear.num_misses);
    assert_eq!(n(EventKind::FalsePositive), m.clear.num_false_positives);
    let d: Vec<f64> = events.iter().filter_map(|e| e.distance).collect();
    assert!(d.iter().all(|&x| (0.0..=0.5).contains(&x)));
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    assert!((mean - m.clear.motp).abs() < 1e-12);
    assert!(events.windows(2).all(|w| w[0].frame <= w[1].frame));
}
