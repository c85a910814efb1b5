//! `peopletrack score --gt GT.csv --hyp HYP.csv (--iou T | --dist-m D) [--json]`: tracking
//! metrics of one hypothesis file against its ground truth (MOTChallenge CSV), through
//! [`peopletrack::eval::mot`]. `run` reads the files; [`render_text`] is pure.

use std::path::{Path, PathBuf};

use anyhow::Context;

use peopletrack::eval::mot::{self, GeometryKind, MatchRule, Metrics, Observation};

const HELP: &str = "\
Input: MOTChallenge CSV, one row per object per frame:
  frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z
With --iou the box columns (pixels) are compared; with --dist-m the ground-plane
columns x,y (metres, as in MOT15's 3-D files) are, and the box columns are ignored.

What the numbers mean (higher is better unless marked):
  HOTA   √(DetA·AssA), averaged over localisation thresholds α = 0.05..0.95
         (Luiten et al. 2021, as TrackEval); DetA: detection, AssA: association,
         LocA: mean similarity (IoU, or 1 − d/(2·METRES) for points) of matches.
  MOTA   1 − (misses + false positives + ID switches) / ground-truth boxes
         (CLEAR MOT, exactly as py-motmetrics 1.4.0).
  MOTP   mean distance of matched pairs: 1 − IoU for boxes (lower is better;
         MOTChallenge prints (1 − MOTP)·100), metres for points.
  IDF1   share of observations that keep the right identity under one global
         trajectory matching (Ristani et al. 2016); IDP/IDR: its precision/recall.
  MT/PT/ML  objects tracked in ≥80 % / 20–80 % / <20 % of their frames.
  FM     fragmentations: a tracked object lost, then found again.

Examples:
  peopletrack score --gt ../shared/real/motmetrics/TUD-Campus/gt.txt \\
                    --hyp ../shared/real/motmetrics/TUD-Campus/test.txt --iou 0.5
  peopletrack score --gt people_gt.csv --hyp people_tracks.csv --dist-m 0.75 --json";

#[derive(Debug, clap::Args)]
#[command(after_long_help = HELP)]
#[command(group = clap::ArgGroup::new("rule").required(true).args(["iou", "dist_m"]))]
pub struct Args {
    /// Ground truth, MOTChallenge CSV.
    #[arg(long, value_name = "GT.csv")]
    pub gt: PathBuf,
    /// Tracker output to score, MOTChallenge CSV.
    #[arg(long, value_name = "HYP.csv")]
    pub hyp: PathBuf,
    /// Match boxes: a pair may match when IoU ≥ MIN_IOU (MOTChallenge uses 0.5).
    #[arg(long, value_name = "MIN_IOU", allow_negative_numbers = true)]
    pub iou: Option<f64>,
    /// Match ground-plane points (columns x,y in metres): a pair may match within METRES.
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    pub dist_m: Option<f64>,
    /// Print every metric (per-α HOTA included) as one JSON object.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let rule = match (args.iou, args.dist_m) {
        (Some(min_iou), _) => MatchRule::Iou { min_iou },
        (None, Some(max_m)) => MatchRule::Euclidean { max_m },
        (None, None) => anyhow::bail!("give --iou or --dist-m"),
    };
    match rule {
        MatchRule::Iou { min_iou } if !(min_iou > 0.0 && min_iou <= 1.0) => {
            anyhow::bail!("--iou {min_iou}: the minimum IoU must lie in (0, 1]")
        }
        MatchRule::Euclidean { max_m } if !(max_m > 0.0 && max_m.is_finite()) => {
            anyhow::bail!(
                "--dist-m {max_m}: the match distance must be a positive number of metres"
            )
        }
        _ => {}
    }
    // Both files at once (each parse is one pass over its text); errors in the order the
    // files are named.
    let (gt, hyp) = rayon::join(
        || read(&args.gt, rule.geometry()),
        || read(&args.hyp, rule.geometry()),
    );
    let gt = gt?;
    if gt.is_empty() {
        anyhow::bail!(
            "{}: no ground-truth rows, so MOTA, IDF1 and HOTA are undefined",
            args.gt.display()
        );
    }
    let hyp = hyp?;
    // the sequence keeps what the metrics need (dense ids and geometry, grouped by frame);
    // the parsed rows go before the metrics run, and no per-frame events are collected
    let sequence = mot::Sequence::new(&gt, &hyp, rule)?;
    drop((gt, hyp));
    let metrics = sequence.metrics();
    if args.json {
        let v = serde_json::json!({
            "gt": args.gt.display().to_string(),
            "hyp": args.hyp.display().to_string(),
            "match": rule,
            "metrics": metrics,
        });
        writeln!(out, "{}", serde_json::to_string_pretty(&v)?)?;
    } else {
        out.write_all(render_text(&metrics, rule).as_bytes())?;
    }
    Ok(())
}

fn read(path: &Path, kind: GeometryKind) -> anyhow::Result<Vec<Observation>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(mot::parse_motchallenge(&text, path, kind)?)
}

/// The metrics as a small aligned table: name, value, what it is.
pub fn render_text(m: &Metrics, rule: MatchRule) -> String {
    let (c, i, h) = (&m.clear, &m.identity, &m.hota);
    let pct = |x: f64| format!("{:.2} %", 100.0 * x);
    let (motp, motp_what) = match rule {
        MatchRule::Iou { .. } => (
            format!("{:.4}", c.motp),
            "mean 1 − IoU of matches (lower is better)",
        ),
        MatchRule::Euclidean { .. } => (
            format!("{:.4} m", c.motp),
            "mean distance of matches (lower is better)",
        ),
    };
    let rule_text = match rule {
        MatchRule::Iou { min_iou } => format!("IoU ≥ {min_iou}"),
        MatchRule::Euclidean { max_m } => format!("distance ≤ {max_m} m"),
    };
    let rows: Vec<(&str, String, String)> = vec![
        ("HOTA", pct(h.hota), "√(DetA · AssA), mean over α".into()),
        ("DetA", pct(h.det_a), "detection accuracy".into()),
        ("AssA", pct(h.ass_a), "association accuracy".into()),
        ("LocA", pct(h.loc_a), "localisation accuracy".into()),
        ("MOTA", pct(c.mota), "1 − (FN + FP + IDSW) / GT".into()),
        ("MOTP", motp, motp_what.into()),
        (
            "IDF1",
            pct(i.idf1),
            format!("IDTP {} IDFP {} IDFN {}", i.idtp, i.idfp, i.idfn),
        ),
        ("IDP", pct(i.idp), "identity precision".into()),
        ("IDR", pct(i.idr), "identity recall".into()),
        ("Recall", pct(c.recall), "TP / GT".into()),
        ("Precision", pct(c.precision), "TP / (TP + FP)".into()),
        (
            "GT",
            c.num_objects.to_string(),
            format!("observations of {} objects", c.num_unique_objects),
        ),
        (
            "TP",
            c.num_detections.to_string(),
            "matches incl. switches".into(),
        ),
        (
            "FP",
            c.num_false_positives.to_string(),
            "false positives".into(),
        ),
        ("FN", c.num_misses.to_string(), "misses".into()),
        (
            "IDSW",
            c.num_switches.to_string(),
            "identity switches".into(),
        ),
        (
            "FM",
            c.num_fragmentations.to_string(),
            "fragmentations".into(),
        ),
        (
            "MT/PT/ML",
            format!(
                "{}/{}/{}",
                c.mostly_tracked, c.partially_tracked, c.mostly_lost
            ),
            "mostly tracked / partially / mostly lost".into(),
        ),
        (
            "Frames",
            c.num_frames.to_string(),
            format!("matching: {rule_text}"),
        ),
    ];
    let w0 = rows.iter().map(|r| r.0.chars().count()).max().unwrap_or(0);
    let w1 = rows.iter().map(|r| r.1.chars().count()).max().unwrap_or(0);
    let mut s = String::new();
    for (name, value, what) in rows {
        let pad0 = w0 - name.chars().count();
        let pad1 = w1 - value.chars().count();
        s.push_str(&format!(
            "{name}{}  {}{value}  {what}\n",
            " ".repeat(pad0),
            " ".repeat(pad1)
        ));
    }
    s
}
