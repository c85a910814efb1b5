//! Head point vs blob centroid under static occlusion: ground error of the triangulated
//! points, unpaired Student t-test at 99 %, and one bar figure per detector.

use std::collections::BTreeMap;

use super::{mean, std};
use crate::eval::stats::{DEFAULT_LEVEL, TTest, student_t};
use crate::pipelines::s004_mohedano_multicam::Params;
use crate::pipelines::s004_mohedano_multicam::scored::Scored;
use crate::pipelines::s004_mohedano_multicam::session::{ASSOCIATION_IOU, CLEAR_VISIBILITY};
use crate::pipelines::s004_mohedano_multicam::tables::HeadCentroidRow;
use crate::report::figure::{Bar, BarPlot, FigureKind, Significance};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};

pub(crate) const OCCLUDED: &str = "static occlusion";
pub(crate) const UNOCCLUDED: &str = "unoccluded";

crate::table_row! {
    /// One detector and set: the two errors and the test between them.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct HeadCentroidTestRow {
        pub detector: String,
        pub set: String,
        pub n: i64,
        pub head_error_m: f64,
        pub head_std_m: f64,
        pub centroid_error_m: f64,
        pub centroid_std_m: f64,
        pub t: f64,
        pub df: f64,
        pub p: f64,
        pub cohens_d: f64,
        pub significant_99: bool,
    }
}

crate::table_row! {
    /// One person at one frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct HeadCentroidSample {
        pub detector: String,
        pub session: String,
        pub frame: i64,
        pub person: i64,
        pub set: String,
        pub head_error_m: f64,
        pub centroid_error_m: f64,
    }
}

/// The set of a row: statically occluded, unoccluded, or neither (not compared).
pub(crate) fn set_of(r: &HeadCentroidRow) -> Option<&'static str> {
    if r.occluded {
        Some(OCCLUDED)
    } else if r.clear {
        Some(UNOCCLUDED)
    } else {
        None
    }
}

/// The test row of one detector and set from the head and centroid errors.
pub(crate) fn test_row(
    det: &str,
    set: &str,
    h: &[f64],
    m: &[f64],
) -> (HeadCentroidTestRow, Option<TTest>) {
    let test = student_t(h, m, DEFAULT_LEVEL).ok();
    let get = |f: fn(&TTest) -> f64| test.as_ref().map_or(f64::NAN, f);
    let row = HeadCentroidTestRow {
        detector: det.to_string(),
        set: set.to_string(),
        n: h.len() as i64,
        head_error_m: mean(h).unwrap_or(f64::NAN),
        head_std_m: std(h).unwrap_or(f64::NAN),
        centroid_error_m: mean(m).unwrap_or(f64::NAN),
        centroid_std_m: std(m).unwrap_or(f64::NAN),
        t: get(|t| t.t),
        df: get(|t| t.df),
        p: get(|t| t.p_two_sided),
        cohens_d: get(|t| t.cohens_d),
        significant_99: test
            .as_ref()
            .is_some_and(|t| t.significant(1.0 - DEFAULT_LEVEL)),
    };
    (row, test)
}

/// Per `(detector, set)`: the head and centroid errors; the detectors in order of appearance;
/// the samples.
type Grouped = (
    BTreeMap<(String, String), (Vec<f64>, Vec<f64>)>,
    Vec<String>,
    Vec<HeadCentroidSample>,
);

fn grouped(s: &Scored) -> Grouped {
    let mut detectors: Vec<String> = Vec::new();
    let mut sets: BTreeMap<(String, String), (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    let mut samples = Vec::new();
    for d in &s.data {
        for r in &d.head_centroid {
            if !detectors.contains(&r.detector) {
                detectors.push(r.detector.clone());
            }
            let Some(set) = set_of(r) else { continue };
            let e = sets
                .entry((r.detector.clone(), set.to_string()))
                .or_default();
            e.0.push(r.head_error_m);
            e.1.push(r.centroid_error_m);
            samples.push(HeadCentroidSample {
                detector: r.detector.clone(),
                session: d.name.clone(),
                frame: r.frame,
                person: r.id,
                set: set.to_string(),
                head_error_m: r.head_error_m,
                centroid_error_m: r.centroid_error_m,
            });
        }
    }
    (sets, detectors, samples)
}

fn bars_figure(det: &str, bars: Vec<Bar>, significance: Vec<Significance>) -> Figure {
    Figure::new(
        format!("head_vs_centroid_{det}"),
        format!("Ground error of triangulated head points vs blob centroids ({det})"),
        FigureKind::Bars(BarPlot {
            y_label: "ground-position error (m), mean ± std".into(),
            bars,
            significance,
        }),
    )
}

pub(super) fn table(
    s: &Scored,
    p: &Params,
    summary: &mut Vec<String>,
) -> anyhow::Result<(Table, Vec<Figure>)> {
    let (sets, detectors, samples) = grouped(s);
    let mut rows = Vec::new();
    let mut figures = Vec::new();
    for det in &detectors {
        let (mut bars, mut sig) = (Vec::new(), Vec::new());
        for set in [OCCLUDED, UNOCCLUDED] {
            let Some((h, m)) = sets.get(&(det.clone(), set.to_string())) else {
                continue;
            };
            let (row, test) = test_row(det, set, h, m);
            let i0 = bars.len();
            for (what, v) in [("head", h), ("centroid", m)] {
                bars.push(Bar {
                    label: format!("{what}, {set}"),
                    value: mean(v).unwrap_or(f64::NAN),
                    error: std(v).unwrap_or(0.0),
                });
            }
            if let Some(t) = &test {
                sig.push(Significance {
                    i: i0,
                    j: i0 + 1,
                    label: format!("p = {:.2e}", t.p_two_sided),
                });
                if set == OCCLUDED && det == &s.main.0 {
                    summary.push(format!(
                        "Under static occlusion ({det}), head-point triangulation errs {:.3} m on the ground vs {:.3} m for blob centroids (n = {} each, Student t = {:.2}, p = {:.2e}).",
                        row.head_error_m, row.centroid_error_m, row.n, t.t, t.p_two_sided
                    ));
                }
            }
            rows.push(row);
        }
        if !bars.is_empty() {
            figures.push(bars_figure(det, bars, sig));
        }
    }
    Ok((
        Table::new(
            "head_vs_centroid",
            "Triangulating head points vs blob centroids: ground-position error under static (desk) occlusion, unpaired Student t-test at 99 %",
            HeadCentroidTestRow::frame(&rows)?,
        )
        .with_precision("t", 2)
        .with_precision("df", 0)
        .with_precision("p", 4)
        .with_precision("cohens_d", 2)
        .with_note(format!("Per person and frame, each camera's detection is associated with the person by box overlap (IoU ≥ {ASSOCIATION_IOU} with the visible ground-truth box); the head points (template top, or the box head of the 3-D run) and the blob centroids (foreground pixels in the template box, or box centre) of the associated cameras (≥ 2) are triangulated by DLT and the ground (x, y) compared with the truth. '{OCCLUDED}': at least one camera sees the person with visibility < {} and no other person's box overlaps theirs there (so furniture hides them); '{UNOCCLUDED}': visibility ≥ {CLEAR_VISIBILITY} in every camera used.", p.occluded_visibility))
        .with_note("Consecutive frames of one person are correlated, so the t-test's n overstates the independent evidence; the effect size (Cohen's d) does not depend on n.")
        .with_note("Paper: argues (§5) that head points are more robust than centroids to static occlusion, without numbers.")
        .with_samples(HeadCentroidSample::frame(&samples)?),
        figures,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hc(occluded: bool, clear: bool) -> HeadCentroidRow {
        HeadCentroidRow {
            detector: "templates".into(),
            frame: 0,
            id: 1,
            cameras: 2,
            occluded,
            clear,
            min_visibility: 0.5,
            head_error_m: 0.1,
            centroid_error_m: 0.3,
        }
    }

    #[test]
    fn rows_fall_into_the_occluded_or_the_unoccluded_set_or_neither() {
        assert_eq!(set_of(&hc(true, false)), Some(OCCLUDED));
        assert_eq!(set_of(&hc(true, true)), Some(OCCLUDED));
        assert_eq!(set_of(&hc(false, true)), Some(UNOCCLUDED));
        assert_eq!(set_of(&hc(false, false)), None);
    }

    #[test]
    fn the_test_row_of_known_samples() {
        // head errors 0.1, 0.2, 0.3; centroid errors 0.5, 0.6, 0.7: means 0.2 and 0.6, both
        // std 0.1, pooled t = −0.4 / (0.1 · sqrt(2/3)) = −4.899, df 4, Cohen's d = −4
        let (r, t) = test_row("templates", OCCLUDED, &[0.1, 0.2, 0.3], &[0.5, 0.6, 0.7]);
        assert!(t.is_some());
        assert_eq!(r.n, 3);
        assert!((r.head_error_m - 0.2).abs() < 1e-12 && (r.centroid_error_m - 0.6).abs() < 1e-12);
        assert!((r.head_std_m - 0.1).abs() < 1e-12);
        assert!((r.t + 4.898979485566356).abs() < 1e-9, "t = {}", r.t);
        assert_eq!(r.df, 4.0);
        assert!((r.cohens_d + 4.0).abs() < 1e-9);
        // p ≈ 0.008 < 0.01
        assert!(r.p < 0.01 && r.p > 0.005, "p = {}", r.p);
        assert!(r.significant_99);
    }

    #[test]
    fn too_few_samples_give_no_test() {
        let (r, t) = test_row("x", UNOCCLUDED, &[0.1], &[0.2]);
        assert!(t.is_none());
        assert!(r.t.is_nan() && !r.significant_99);
        assert_eq!(r.n, 1);
    }
}
