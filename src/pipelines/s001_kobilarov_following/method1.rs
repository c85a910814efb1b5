//! Method 1 of seed 001 (§IV, after Jung & Sukhatme) on the closed-loop logs: every
//! `method1_every`-th omni frame through [`crate::vision::egomotion::Method1`] (perspective
//! views, KLT on the raw image, bilinear egomotion compensation, frame differencing, particle
//! filter + EM); a frame is *lost* when there is no detection or its bearing is farther than
//! `method1_lost_deg` from the target's true bearing in the camera frame. The paper's fig. 3
//! claim — frequent losses, unreliable above 1 m/s — is then the loss rate per robot-speed
//! bin ([`loss_table`]).

use image::RgbImage;
use nalgebra::Point3;

use super::params::Params;
use super::tables::Method1Row;
use crate::frames::truth::Stamped;
use crate::geometry::camera::Paracatadioptric;
use crate::groundtruth::PeopleFrame;
use crate::log::TfBuffer;
use crate::rng;
use crate::time::Nanos;
use crate::vision::egomotion::{self, Method1};

/// Method 1's state over one session.
pub struct State {
    m: Method1,
    camera_frame: String,
    target_id: u32,
    chest_m: f64,
    lost_rad: f64,
}

impl State {
    pub fn new(
        model: &Paracatadioptric,
        p: &Params,
        camera_frame: String,
        log: &std::path::Path,
    ) -> anyhow::Result<State> {
        let name = log
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        let seed = rng::hash(0x5eed_0001, &[xxhash_rust::xxh3::xxh3_64(name.as_bytes())]);
        Ok(State {
            m: Method1::new(model, &p.method1, seed)
                .map_err(|e| anyhow::anyhow!("{}: method 1: {e}", log.display()))?,
            camera_frame,
            target_id: p.target_id,
            chest_m: p.follower.chest_height_m,
            lost_rad: p.method1_lost_deg.to_radians(),
        })
    }

    /// One omni frame: `(index, stamp, seconds since the first scan)`.
    pub fn frame(
        &mut self,
        tf: &TfBuffer,
        gt: &Stamped<PeopleFrame>,
        tolerance_ns: u64,
        (idx, stamp, t): (i64, Nanos, f64),
        img: &RgbImage,
    ) -> anyhow::Result<Option<Method1Row>> {
        let out = self
            .m
            .step(img)
            .map_err(|e| anyhow::anyhow!("method 1 at frame {idx}: {e}"))?;
        Ok(self.row(tf, gt, tolerance_ns, (idx, stamp, t), &out))
    }

    fn row(
        &self,
        tf: &TfBuffer,
        gt: &Stamped<PeopleFrame>,
        tolerance_ns: u64,
        (idx, stamp, t): (i64, Nanos, f64),
        out: &egomotion::Method1Output,
    ) -> Option<Method1Row> {
        let est = out.detection.map(|d| d.azimuth);
        let person = gt
            .nearest(stamp, tolerance_ns)?
            .people
            .iter()
            .find(|q| q.id == self.target_id)
            .map(|q| (q.x, q.y))?;
        let cam_from_map = tf.lookup(&self.camera_frame, "map", stamp).ok()?;
        let q = cam_from_map * Point3::new(person.0, person.1, self.chest_m);
        let truth = (q.x.hypot(q.y) > 1e-9).then(|| q.y.atan2(q.x));
        let v = robot_speed(tf, stamp)?;
        Some(Method1Row {
            frame_idx: idx,
            t_s: t,
            robot_v: v,
            est_azimuth: est,
            true_azimuth: truth,
            lost: truth.is_none_or(|a| egomotion::is_lost(est, a, self.lost_rad)),
            features: out.features_tracked as i64,
            fallback_views: out.fallback_views as i64,
        })
    }
}

/// The robot's true speed at `at` from `map <- base_link` 0.1 s apart.
fn robot_speed(tf: &TfBuffer, at: Nanos) -> Option<f64> {
    let dt = 100_000_000u64;
    let a = tf
        .lookup("map", "base_link", Nanos(at.0.saturating_sub(dt)))
        .ok()?;
    let b = tf.lookup("map", "base_link", at).ok()?;
    Some((b.translation.vector - a.translation.vector).xy().norm() / (dt as f64 * 1e-9))
}

crate::table_row! {
    /// Method 1's loss rate per robot-speed bin, all sessions: `method1_loss`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct LossRow {
        pub speed_lo: f64,
        pub speed_hi: f64,
        pub frames: i64,
        pub lost: i64,
        pub loss_rate: f64,
    }
}

/// The loss rate per speed bin over every session's method-1 rows.
pub fn loss_table(rows: &[Method1Row], bin: f64) -> Vec<LossRow> {
    let samples: Vec<(f64, bool)> = rows.iter().map(|r| (r.robot_v, r.lost)).collect();
    egomotion::loss_by_speed(&samples, bin)
        .into_iter()
        .map(|b| LossRow {
            speed_lo: b.lo,
            speed_hi: b.hi,
            frames: b.frames as i64,
            lost: b.lost as i64,
            loss_rate: b.rate,
        })
        .collect()
}
