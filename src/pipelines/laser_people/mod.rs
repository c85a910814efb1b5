//! `laser_people` — laser people detection and tracking ([`crate::laser`]) scored on real and
//! synthetic laser logs.
//!
//! Per session ([`session`], cached as the rows of [`tables`]): every scan of the sequence's
//! laser topic through every method of [`methods`] (`legs`: seed 002 leg model → people →
//! `PeopleTracker`; `nearest`: the midpoint of the two legs nearest to the laser, no filter,
//! one id), with the ground truth on its scans, all in the laser frame. The aggregation
//! ([`aggregate`]) scores each sequence × method with CLEAR MOT, IDF1 and HOTA under the
//! sequence's protocol ([`params::Sequence`]: scored scans, bearing wedge, range), runs paired
//! t-tests of the methods' position errors, writes the tracks as CSV, draws the figures
//! ([`figures`]: a top view per sequence, MOTA and MOTP per method; from the poses and sampled
//! returns that [`view`] caches), puts the real sequences beside the paper's Table III under
//! the paper's own protocol for each benchmark ([`paper`]), and with `--write-tracks` writes the tracks back into copies
//! of the logs as Foxglove markers ([`markers`]). The real sequences
//! (Leigh et al., ICRA 2015) are read in place from `../shared/real/laser/`; listed ones that
//! are absent get SKIPPED rows.

mod aggregate;
mod classifier;
mod figures;
mod fp_causes;
pub mod learned;
mod markers;
mod methods;
mod paper;
mod params;
mod session;
mod tables;
mod view;

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::progress::Progress;
use crate::run::config::Invalid;
use crate::run::schemas::{TableDoc, table};
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

pub use learned::LearnedParams;
pub use params::{Params, Sequence};

pub struct LaserPeople;

/// Every per-session table and what a row of it is (`docs/schemas.md`).
const SESSION_TABLES: &[TableDoc] = &[
    table(
        tables::SESSION,
        "What one session read (one row): topics, ground-truth kind, fixed frame, scans, \
         odometry source and its error, ground-truth rows kept and dropped, skipped messages.",
    ),
    table(
        tables::SCANS,
        "One scan: index, stamps, whether TF placed it, legs and people the leg model found.",
    ),
    table(
        tables::TRUTH,
        "A ground-truth person on a scan, laser frame (m).",
    ),
    table(
        tables::TRACKS,
        "A hypothesis of one detector on a scan: `x`, `y` in the laser frame, `world_x`, \
         `world_y` in the fixed frame (m).",
    ),
    table(
        view::POSES,
        "The laser on one scan: its frame id and its pose (`x`, `y` m, `yaw` rad) in the fixed frame.",
    ),
    table(
        view::POINTS,
        "One return of a sampled scan in the fixed frame (m, rounded to 1 cm), for the top views.",
    ),
];

impl Experiment for LaserPeople {
    const KIND: &'static str = "laser_people";
    const VERSION: u32 = 6;
    const SESSION_TABLES: &'static [TableDoc] = SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        params::validate(p)
    }

    /// Topics differ per sequence, so none is required here: a session without its laser
    /// topic fails in `process` with the topic named (a listed skip).
    fn plan(p: &Params, _: &BTreeMap<String, String>) -> Vec<Stage> {
        let mut scans: Vec<String> = p.sequences.iter().map(|s| s.scan_topic.clone()).collect();
        scans.push(p.synthetic.scan_topic.clone());
        scans.sort();
        scans.dedup();
        let mut gt: Vec<String> = p.sequences.iter().map(|s| s.gt_topic.clone()).collect();
        gt.push(p.synthetic.gt_topic.clone());
        gt.sort();
        gt.dedup();
        vec![
            Stage {
                name: "laser methods (leg model + tracker, nearest baseline, …)".into(),
                requires: vec![],
                optional: [scans, vec!["/tf".into(), "/tf_static".into()]].concat(),
            },
            Stage {
                name: "ground truth".into(),
                requires: vec![],
                optional: gt,
            },
        ]
    }

    /// The learned detectors' training data (read when the first session or the aggregation
    /// trains them; see [`learned`]): the real training folder and the synthetic logs only
    /// when a learned method is listed.
    fn external_inputs(p: &Params) -> Vec<PathBuf> {
        let mut out = Vec::new();
        for &m in &p.methods {
            let l = p.learned_for(m);
            match m.source() {
                Some(learned::Source::Real) => out.push(PathBuf::from(&l.training_dir)),
                Some(learned::Source::Synthetic) => {
                    for g in &l.synthetic_sessions {
                        out.extend(glob::glob(g).into_iter().flatten().flatten());
                    }
                }
                None => {}
            }
            if let Some(f) = &l.model {
                out.push(PathBuf::from(f));
            }
        }
        out.sort();
        out.dedup();
        out
    }

    fn process(
        s: &Session,
        p: &Params,
        _: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        session::process(s, p, bar)
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        let (mut out, data, results) = aggregate::run(ctx, p)?;
        out.figures.extend(figures::all(ctx, p, &data, &results)?);
        if let Some(dir) = ctx.write_tracks {
            out.summary.extend(markers::export(ctx, p, &data, dir)?);
        }
        Ok(out)
    }
}
