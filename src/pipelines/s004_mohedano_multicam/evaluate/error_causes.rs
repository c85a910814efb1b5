//! The template chain's error analysis (issue 32): every missed person and every false
//! detection of the `detections_2d` scoring counted by its cause (`session::errors` names
//! them), over all cameras and sessions.

use std::collections::BTreeMap;

use crate::pipelines::s004_mohedano_multicam::scored::Scored;
use crate::pipelines::s004_mohedano_multicam::tables::Error2dRow;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::vision::template::THRESHOLD_RANGE;

/// Row label of each kind's total.
const TOTAL: &str = "all";

crate::table_row! {
    /// One cause of one kind of error (or the kind's total).
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct CauseRow {
        /// "miss" or "false".
        pub kind: String,
        pub cause: String,
        pub errors: i64,
        /// Of the kind's errors.
        pub share: f64,
        /// Misses whose best candidate near the head scores at least the paper's lowest
        /// threshold (0.6); false detections scoring under its highest (0.75).
        pub flips_in_paper_range: i64,
        /// Misses of standing people (slower than `STANDING_MPS`); 0 for false detections.
        pub standing: i64,
    }
}

/// Per kind (misses first): the causes by count (most first, then by name), then the total.
pub(crate) fn rows<'a>(rows: impl IntoIterator<Item = &'a Error2dRow>) -> Vec<CauseRow> {
    use crate::pipelines::s004_mohedano_multicam::session::{MISS, STANDING_MPS};
    // (kind, cause) → (errors, flips, standing)
    let mut acc: BTreeMap<(String, String), (i64, i64, i64)> = BTreeMap::new();
    for r in rows {
        let miss = r.kind == MISS;
        let flips = if miss {
            r.set_score >= THRESHOLD_RANGE.0
        } else {
            r.det_score < THRESHOLD_RANGE.1
        };
        let standing = miss && r.speed_mps < STANDING_MPS;
        for cause in [r.cause.as_str(), TOTAL] {
            let e = acc.entry((r.kind.clone(), cause.to_string())).or_default();
            e.0 += 1;
            e.1 += i64::from(flips);
            e.2 += i64::from(standing);
        }
    }
    let mut kinds: Vec<&String> = acc.keys().map(|k| &k.0).collect();
    kinds.dedup();
    // misses first
    kinds.sort_by_key(|k| (k.as_str() != MISS, k.to_string()));
    let mut out = Vec::new();
    for kind in kinds {
        let total = acc[&(kind.clone(), TOTAL.to_string())].0;
        let mut causes: Vec<(&String, &(i64, i64, i64))> = acc
            .iter()
            .filter(|((k, c), _)| k == kind && c != TOTAL)
            .map(|((_, c), v)| (c, v))
            .collect();
        causes.sort_by(|a, b| b.1.0.cmp(&a.1.0).then(a.0.cmp(b.0)));
        let total_row = (&TOTAL.to_string(), &acc[&(kind.clone(), TOTAL.to_string())]);
        for (cause, v) in causes.into_iter().chain([total_row]) {
            out.push(CauseRow {
                kind: kind.clone(),
                cause: cause.clone(),
                errors: v.0,
                share: v.0 as f64 / total.max(1) as f64,
                flips_in_paper_range: v.1,
                standing: v.2,
            });
        }
    }
    out
}

pub(super) fn table(s: &Scored, summary: &mut Vec<String>) -> anyhow::Result<Option<Table>> {
    let rows = rows(s.data.iter().flat_map(|d| &d.errors_2d));
    if rows.is_empty() {
        return Ok(None);
    }
    let top = |kind: &str| {
        rows.iter()
            .find(|r| r.kind == kind && r.cause != TOTAL)
            .map(|r| format!("{} ({:.0} %)", r.cause, 100.0 * r.share))
            .unwrap_or_else(|| "none".into())
    };
    use crate::pipelines::s004_mohedano_multicam::session::{FALSE, MISS};
    summary.push(format!(
        "template chain errors: the largest cause of misses is {}, of false detections {}",
        top(MISS),
        top(FALSE)
    ));
    Ok(Some(
        Table::new(
            "error_causes_2d",
            "The template chain's errors by cause: every missed person and every false detection of detections_2d",
            CauseRow::frame(&rows)?,
        )
        .with_precision("share", 3)
        .with_note("A miss is followed through the chain and named by the first stage that lost the person: the image border; a candidate within the matching tolerance above the threshold suppressed by a better detection (a neighbour's: merged; one on the same person with its head beyond the tolerance: mislocated); no template the calibration allows there fits but another of the set does (template choice); none of the set fits but the person's own silhouette (true projected height and tilt, same margin) does (template set); or not even that (the mask: desk or people occlusion, standing and absorbed, weak foreground when pixels are missing; merged with a neighbour, shadow, extra foreground when the window's margin holds extra). A false detection: on several people (merged), on a person matched to another detection (split), on an unmatched person (mislocated), else by its ground point: near a person (shadow), where a person stood at some frame (ghost or trail), or clutter. Module doc of `session::errors` for the definitions.")
        .with_note(format!("flips_in_paper_range: misses whose best candidate near the head scores at least {} (the paper's lowest threshold) and false detections scoring under {} (its highest): the errors the threshold alone could turn within the paper's range.", THRESHOLD_RANGE.0, THRESHOLD_RANGE.1)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(kind: &str, cause: &str, set: f64, det: f64, speed: f64) -> Error2dRow {
        Error2dRow {
            frame: 0,
            camera: "cam_0".into(),
            kind: kind.into(),
            cause: cause.into(),
            person: 1,
            visibility: 1.0,
            speed_mps: speed,
            exact_score: f64::NAN,
            any_score: f64::NAN,
            set_score: set,
            det_score: det,
        }
    }

    #[test]
    fn causes_are_counted_per_kind_most_first_with_the_kinds_total() {
        let r = rows(&[
            e("false", "shadow", f64::NAN, 0.72, f64::NAN),
            e("miss", "weak foreground", 0.5, f64::NAN, 1.0),
            e("miss", "desk occlusion", 0.65, f64::NAN, 0.1),
            e("miss", "desk occlusion", 0.62, f64::NAN, 1.0),
            e("false", "clutter", f64::NAN, 0.8, f64::NAN),
            e("false", "shadow", f64::NAN, 0.76, f64::NAN),
        ]);
        let got: Vec<(&str, &str, i64, i64, i64)> = r
            .iter()
            .map(|x| {
                (
                    x.kind.as_str(),
                    x.cause.as_str(),
                    x.errors,
                    x.flips_in_paper_range,
                    x.standing,
                )
            })
            .collect();
        assert_eq!(
            got,
            [
                ("miss", "desk occlusion", 2, 2, 1),
                ("miss", "weak foreground", 1, 0, 0),
                ("miss", "all", 3, 2, 1),
                ("false", "shadow", 2, 1, 0),
                ("false", "clutter", 1, 0, 0),
                ("false", "all", 3, 1, 0),
            ]
        );
        assert!((r[0].share - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(r[2].share, 1.0);
    }
}
