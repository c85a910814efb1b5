//! The 3-D runs (§5) on the 2-D objects kept of every frame: the configured one, the `N_app`
//! sweep and the other selection rule, for each source of 2-D objects; their tracks and search
//! statistics as rows.

use rayon::prelude::*;

use super::super::Params;
use super::pass::FrameRec;
use super::selection_label;
use crate::geometry::triangulate::CalibratedView;
use crate::pipelines::s004_mohedano_multicam::tables::{TrackRow, VariantRow};
use crate::time::Nanos;
use crate::track::cylinders::{Cylinder, CylinderParams, CylinderTracker, Object2d, Selection};

pub(crate) fn cylinder_params(
    p: &Params,
    dt_s: f64,
    selection: Selection,
    n_app: u32,
) -> CylinderParams {
    CylinderParams {
        p_th_px: p.p_th_px,
        n_app,
        // the paper: N_dis = N_app is a reasonable choice; the sweep keeps them equal
        n_dis: if n_app == p.n_app { p.n_dis } else { n_app },
        selection,
        head_height_m: (p.head_height_m[0], p.head_height_m[1]),
        room_m: p.room_m,
        room_margin_m: p.room_margin_m,
        gate_m: p.gate_m,
        accel_sigma: p.accel_sigma_mps2,
        max_combinations: p.max_combinations,
        association: p.association,
        ground_separation_m: p.ground_separation_m,
        occupancy: p.occupancy,
        dt_s,
        ..CylinderParams::default()
    }
}

/// One 3-D run's output.
pub(crate) struct VariantOut {
    /// Cylinders per frame.
    pub tracks: Vec<Vec<Cylinder>>,
    pub combinations: usize,
    pub pruned_frames: usize,
    pub promoted: usize,
    pub discarded: usize,
}

impl VariantOut {
    /// No frames yet, room for `frames`.
    fn empty(frames: usize) -> Self {
        Self {
            tracks: Vec::with_capacity(frames),
            combinations: 0,
            pruned_frames: 0,
            promoted: 0,
            discarded: 0,
        }
    }
}

pub(crate) fn run_variant(
    views: &[CalibratedView],
    params: CylinderParams,
    frames: &[Vec<Object2d>],
) -> anyhow::Result<VariantOut> {
    let mut tracker = CylinderTracker::new(views.to_vec(), params)?;
    let mut out = VariantOut::empty(frames.len());
    for objs in frames {
        let (cyl, stats) = tracker.step(objs);
        out.combinations += stats.combinations;
        out.pruned_frames += usize::from(stats.pruned);
        out.promoted += stats.promoted;
        out.discarded += stats.discarded;
        out.tracks.push(cyl);
    }
    Ok(out)
}

/// The configured association frame by frame: a fresh tracker with `N_app = N_dis = 1`
/// every frame, so that nothing carries over (the 3-D association alone).
pub(crate) fn run_per_frame(
    views: &[CalibratedView],
    params: CylinderParams,
    frames: &[Vec<Object2d>],
) -> anyhow::Result<VariantOut> {
    let params = CylinderParams {
        n_app: 1,
        n_dis: 1,
        ..params
    };
    let mut out = VariantOut::empty(frames.len());
    for objs in frames {
        let mut tracker = CylinderTracker::new(views.to_vec(), params)?;
        let (cyl, stats) = tracker.step(objs);
        out.combinations += stats.combinations;
        out.pruned_frames += usize::from(stats.pruned);
        out.tracks.push(cyl);
    }
    Ok(out)
}

/// `(source, selection, N_app)` of one run: the sweep over `N_app` (with the configured one)
/// and the other selection rule at the configured `N_app`, per source.
pub(crate) fn variants(p: &Params, sources: usize) -> Vec<(usize, Selection, u32)> {
    let other = match p.selection {
        Selection::Corrected => Selection::Mean,
        Selection::Mean => Selection::Corrected,
    };
    let mut n_apps: Vec<u32> = p.n_app_sweep.clone();
    n_apps.push(p.n_app);
    n_apps.sort_unstable();
    n_apps.dedup();
    let mut out = Vec::new();
    for si in 0..sources {
        for &n in &n_apps {
            out.push((si, p.selection, n));
        }
        out.push((si, other, p.n_app));
    }
    out
}

/// The main run's 3-D stage timed frame by frame (MEASURED): `(2-D objects, seconds)`, each
/// frame the fastest of 3 steps on clones of the tracker (the clone is not timed); the real
/// tracker then steps once, so the states are those of the run.
pub(crate) fn time_run(
    views: &[CalibratedView],
    params: CylinderParams,
    frames: &[Vec<Object2d>],
) -> anyhow::Result<Vec<(usize, f64)>> {
    let mut tracker = CylinderTracker::new(views.to_vec(), params)?;
    let mut out = Vec::with_capacity(frames.len());
    for objs in frames {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let mut t = tracker.clone();
            let start = std::time::Instant::now();
            let r = t.step(objs);
            best = best.min(start.elapsed().as_secs_f64());
            std::hint::black_box(r);
        }
        tracker.step(objs);
        out.push((objs.len(), best));
    }
    Ok(out)
}

/// The rows of every run.
#[derive(Default)]
pub(crate) struct RunRows {
    pub tracks: Vec<TrackRow>,
    pub variants: Vec<VariantRow>,
}

/// Every run of every source (in parallel), as rows in run order.
pub(crate) fn run_all(
    p: &Params,
    views: &[CalibratedView],
    dt_s: f64,
    sources: &[(&'static str, Vec<Vec<Object2d>>)],
    frames: &[FrameRec],
) -> anyhow::Result<RunRows> {
    let variants = variants(p, sources.len());
    let results: Vec<anyhow::Result<VariantOut>> = variants
        .par_iter()
        .map(|&(si, sel, n)| run_variant(views, cylinder_params(p, dt_s, sel, n), &sources[si].1))
        .collect();
    let stamps: Vec<Nanos> = frames.iter().map(|f| f.stamp).collect();
    let mut rows = RunRows::default();
    let mut labelled: Vec<(String, Selection, u32, anyhow::Result<VariantOut>)> = variants
        .iter()
        .zip(results)
        .map(|(&(si, sel, n), r)| (sources[si].0.to_string(), sel, n, r))
        .collect();
    if p.decompose {
        let params = cylinder_params(p, dt_s, p.selection, p.n_app);
        labelled.push((
            format!("{}_per_frame", sources[0].0),
            p.selection,
            p.n_app,
            run_per_frame(views, params, &sources[0].1),
        ));
    }
    for (detector, sel, n, r) in labelled {
        let r = r?;
        let (detector, selection) = (detector.as_str(), selection_label(sel));
        rows.variants.push(VariantRow {
            detector: detector.to_string(),
            selection: selection.to_string(),
            n_app: i64::from(n),
            combinations: r.combinations as i64,
            pruned_frames: r.pruned_frames as i64,
            promoted: r.promoted as i64,
            discarded: r.discarded as i64,
        });
        let run = Run {
            detector,
            selection,
            n_app: n,
            cameras: &p.cameras,
        };
        for (k, cyls) in r.tracks.iter().enumerate() {
            rows.tracks
                .extend(cyls.iter().map(|c| run.row(k, stamps[k], stamps[0], c)));
        }
    }
    Ok(rows)
}

/// The labels of one run.
pub(crate) struct Run<'a> {
    pub detector: &'a str,
    pub selection: &'a str,
    pub n_app: u32,
    pub cameras: &'a [String],
}

impl Run<'_> {
    /// One cylinder at frame `k` as a track row.
    pub fn row(&self, k: usize, stamp: Nanos, t0: Nanos, c: &Cylinder) -> TrackRow {
        let m = c.measured.as_ref();
        TrackRow {
            detector: self.detector.to_string(),
            selection: self.selection.to_string(),
            n_app: i64::from(self.n_app),
            frame: k as i64,
            stamp_ns: stamp.0 as i64,
            t_s: (stamp.0.saturating_sub(t0.0)) as f64 * 1e-9,
            id: i64::from(c.id),
            x_m: c.x_m,
            y_m: c.y_m,
            vx_mps: c.vx_mps,
            vy_mps: c.vy_mps,
            height_m: c.height_m,
            radius_m: c.radius_m,
            cameras: c.support.len() as i64,
            support: support_text(self.cameras, &c.support),
            e_m_px: m.map(|h| h.e_m_px),
            meas_x_m: m.map(|h| h.head_m.x),
            meas_y_m: m.map(|h| h.head_m.y),
            meas_height_m: m.map(|h| h.head_m.z),
            meas_radius_m: m.map(|h| h.radius_m).filter(|r| r.is_finite()),
        }
    }
}

/// Supporting cameras as `camera:2-D id`, space separated.
pub(crate) fn support_text(cameras: &[String], support: &[(usize, u32)]) -> String {
    support
        .iter()
        .map(|(c, id)| format!("{}:{id}", cameras[*c]))
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sweep_includes_the_configured_n_app_once_and_the_other_rule_runs_at_it() {
        let p = Params {
            n_app_sweep: vec![3, 1, 5],
            n_app: 4,
            selection: Selection::Corrected,
            ..Params::default()
        };
        let v = variants(&p, 2);
        let first: Vec<(usize, Selection, u32)> = v[..5].to_vec();
        assert_eq!(
            first,
            [
                (0, Selection::Corrected, 1),
                (0, Selection::Corrected, 3),
                (0, Selection::Corrected, 4),
                (0, Selection::Corrected, 5),
                (0, Selection::Mean, 4),
            ]
        );
        assert_eq!(v.len(), 10);
        assert_eq!(v[9], (1, Selection::Mean, 4));
    }

    #[test]
    fn the_sweep_keeps_n_dis_equal_to_n_app_except_at_the_configured_pair() {
        let p = Params {
            n_app: 5,
            n_dis: 7,
            ..Params::default()
        };
        assert_eq!(cylinder_params(&p, 0.04, Selection::Mean, 5).n_dis, 7);
        assert_eq!(cylinder_params(&p, 0.04, Selection::Mean, 3).n_dis, 3);
    }

    #[test]
    fn support_names_the_cameras_and_their_2d_ids() {
        let cams = vec!["a".to_string(), "b".to_string()];
        assert_eq!(support_text(&cams, &[(1, 4), (0, 2)]), "b:4 a:2");
        assert_eq!(support_text(&cams, &[]), "");
    }
}
