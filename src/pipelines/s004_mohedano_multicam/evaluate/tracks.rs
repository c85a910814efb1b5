//! The main run's 3-D tracks: one row per track, and per frame and person in the samples.

use std::collections::BTreeMap;

use super::mean;
use crate::pipelines::s004_mohedano_multicam::scored::Scored;
use crate::pipelines::s004_mohedano_multicam::tables::TrackRow;
use crate::report::Table;
use crate::report::rows::Rows;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// One track of the main run.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct TrackSummary {
            pub session: String,
            pub id: i64,
            pub first_s: f64,
            pub last_s: f64,
            pub frames: i64,
            pub supported_frames: i64,
            pub mean_x_m: f64,
            pub mean_y_m: f64,
            pub mean_height_m: f64,
            pub mean_radius_m: f64,
            pub mean_cameras: f64,
            pub mean_E_m_px: Option<f64>,
        }
    }

    crate::table_row! {
        /// One track at one frame.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct TrackSample {
            pub session: String,
            pub frame: i64,
            pub t_s: f64,
            pub id: i64,
            pub x_m: f64,
            pub y_m: f64,
            pub height_m: f64,
            pub radius_m: f64,
            pub cameras: i64,
            pub support: String,
            pub E_m_px: Option<f64>,
        }
    }
}
pub(crate) use rows::{TrackSample, TrackSummary};

/// One track's frames (in frame order) summarised.
pub(crate) fn summary(session: &str, id: i64, ix: &[&TrackRow]) -> TrackSummary {
    let avg = |f: fn(&TrackRow) -> f64| ix.iter().map(|r| f(r)).sum::<f64>() / ix.len() as f64;
    let sup: Vec<f64> = ix
        .iter()
        .filter(|r| r.cameras > 0)
        .map(|r| r.cameras as f64)
        .collect();
    let es: Vec<f64> = ix.iter().filter_map(|r| r.e_m_px).collect();
    TrackSummary {
        session: session.to_string(),
        id,
        first_s: ix.first().map_or(f64::NAN, |r| r.t_s),
        last_s: ix.last().map_or(f64::NAN, |r| r.t_s),
        frames: ix.len() as i64,
        supported_frames: sup.len() as i64,
        mean_x_m: avg(|r| r.x_m),
        mean_y_m: avg(|r| r.y_m),
        mean_height_m: avg(|r| r.height_m),
        mean_radius_m: avg(|r| r.radius_m),
        mean_cameras: if sup.is_empty() {
            f64::NAN
        } else {
            sup.iter().sum::<f64>() / sup.len() as f64
        },
        mean_E_m_px: mean(&es),
    }
}

fn sample(session: &str, r: &TrackRow) -> TrackSample {
    TrackSample {
        session: session.to_string(),
        frame: r.frame,
        t_s: r.t_s,
        id: r.id,
        x_m: r.x_m,
        y_m: r.y_m,
        height_m: r.height_m,
        radius_m: r.radius_m,
        cameras: r.cameras,
        support: r.support.clone(),
        E_m_px: r.e_m_px,
    }
}

pub(super) fn table(s: &Scored) -> anyhow::Result<Table> {
    let mut summaries = Vec::new();
    let mut samples = Vec::new();
    for d in &s.data {
        let mut by_id: BTreeMap<i64, Vec<&TrackRow>> = BTreeMap::new();
        for r in d.rows(&s.main) {
            by_id.entry(r.id).or_default().push(r);
            samples.push(sample(&d.name, r));
        }
        for (id, ix) in by_id {
            summaries.push(summary(&d.name, id, &ix));
        }
    }
    Ok(Table::new(
        "tracks",
        format!(
            "3-D tracks ({} detector, {} selection, N_app = {}): one row per track; per frame and person in the samples",
            s.main.0, s.main.1, s.main.2
        ),
        TrackSummary::frame(&summaries)?,
    )
    .with_precision("first_s", 2)
    .with_precision("last_s", 2)
    .with_precision("mean_cameras", 2)
    .with_precision("mean_E_m_px", 2)
    .with_note("Per frame: ground position, height and radius (Kalman-smoothed), supporting cameras as `camera:2-D id`, E_m of the supporting combination (empty while the track coasts) — in tracks.samples.parquet and in each session's tracks.parquet (all runs).")
    .with_samples(TrackSample::frame(&samples)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s004_mohedano_multicam::evaluate::testdata;

    #[test]
    fn one_summary_per_track_of_the_main_run_and_one_sample_per_frame() {
        let s = testdata::scored();
        let t = table(&s).expect("table");
        let rows = TrackSummary::read(&t.df).expect("rows");
        // the main run (templates, E_c, 5): one track, frames 3–9, 3 cameras, E_m 2 px
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        assert_eq!((r.id, r.frames, r.supported_frames), (7, 7, 7));
        assert!((r.first_s - 0.12).abs() < 1e-12 && (r.last_s - 0.36).abs() < 1e-12);
        // x: 1 + 0.1 k + offset over k = 3..9 (offsets 0.7, 0.7, then 0.1 five times)
        let want_x = (3..10).map(|k| 1.0 + 0.1 * f64::from(k)).sum::<f64>() / 7.0 + 1.9 / 7.0;
        assert!((r.mean_x_m - want_x).abs() < 1e-12);
        assert_eq!((r.mean_cameras, r.mean_E_m_px), (3.0, Some(2.0)));
        let samples = TrackSample::read(t.samples.as_ref().expect("samples")).expect("samples");
        assert_eq!(samples.len(), 7);
        assert_eq!(samples[0].frame, 3);
    }

    #[test]
    fn a_track_without_support_has_no_mean_cameras() {
        let mut r = testdata::session().tracks[0].clone();
        r.cameras = 0;
        r.e_m_px = None;
        let s = summary("s", 1, &[&r]);
        assert!(s.mean_cameras.is_nan());
        assert_eq!((s.supported_frames, s.mean_E_m_px), (0, None));
    }
}
