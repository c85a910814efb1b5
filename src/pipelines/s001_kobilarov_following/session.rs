//! The per-session stage of a synthetic (closed-loop) log, one pass in time order:
//!
//! - every scan of `scan_topic` placed in the robot's odometry frame by TF (what the robot
//!   itself knew), the latest omni frame at or before it with the camera's pose then;
//! - every replayed method ([`super::replay`]) stepped on it, its estimate moved into `map`
//!   (`map <- odom` from TF) and compared with the ground truth of that instant;
//! - the ground truth at the scan: the robot's true pose and speed (`map <- base_link`, which
//!   the synthesizer makes exact), the target, and the laser's view of it ([`super::scene`]);
//! - method 1 ([`super::method1`]) on every `method1_every`-th omni frame;
//! - the closed loop's own logged tracker output ([`super::closed_loop`]).
//!
//! Real laser logs go to [`super::real`].

use anyhow::Context;
use image::RgbImage;
use nalgebra::{Isometry3, Point3};

use super::params::{self, Params};
use super::pose::{self, Tilt};
use super::replay::{self, Runner};
use super::tables::{self, ColourRow, Method1Row, TrackRow, TruthRow};
use super::{closed_loop, method1, real, scene};
use crate::frames::camera as camera_frames;
use crate::frames::laser::{self as laser_frames, LaserFrame, LaserOptions};
use crate::frames::{rig, truth};
use crate::geometry::camera::{CameraModel, Paracatadioptric};
use crate::groundtruth::{PEOPLE_TOPIC, PeopleFrame};
use crate::laser::follow::{ScanObs, StepOutput};
use crate::laser::points::{self, ScanGeometry};
use crate::log::{SessionLog, TfBuffer};
use crate::progress::Progress;
use crate::report::rows::Rows;
use crate::run::{Session, SessionTables};
use crate::time::Nanos;

/// Process one session (see the module doc).
pub(super) fn process(
    s: &Session,
    p: &Params,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let stem = s
        .info
        .path
        .file_stem()
        .map(|x| x.to_string_lossy().to_string())
        .unwrap_or_default();
    if let Some(seq) = p.real_sequence(&stem) {
        return real::process(s, p, seq, bar);
    }
    synthetic(s, p, bar)
}

/// What stays fixed over a session.
struct Ctx<'a> {
    log: &'a SessionLog,
    p: &'a Params,
    tf: TfBuffer,
    gt: truth::Stamped<PeopleFrame>,
    model: Option<Paracatadioptric>,
    camera_frame: String,
    laser_frame: String,
    tilt: Tilt,
    t0: Nanos,
    tolerance_ns: u64,
}

impl Ctx<'_> {
    fn t_s(&self, t: Nanos) -> f64 {
        (t.0 as f64 - self.t0.0 as f64) * 1e-9
    }

    fn map_from(&self, frame: &str, at: Nanos) -> Option<Isometry3<f64>> {
        self.tf.lookup("map", frame, at).ok()
    }

    /// `fixed <- frame` as the robot knew it (see [`pose`]).
    fn fixed_from(&self, frame: &str, at: Nanos) -> Option<Isometry3<f64>> {
        let p = self.p;
        pose::fixed_from(
            &self.tf,
            &self.tilt,
            &p.fixed_frame,
            &p.base_frame,
            frame,
            at,
        )
    }
}

fn synthetic(s: &Session, p: &Params, bar: &dyn Progress) -> anyhow::Result<SessionTables> {
    let log = &s.log;
    let file = log.path().display().to_string();
    if log.summary().channel(&p.scan_topic).is_none() {
        anyhow::bail!("{file}: missing laser topic {}", p.scan_topic);
    }
    let (gt, _) = truth::people(log, PEOPLE_TOPIC)
        .with_context(|| format!("{file}: ground truth {PEOPLE_TOPIC}"))?;
    let tf = TfBuffer::from_log(log, 0.5)?;
    let info_topic = format!("/{}/camera_info", p.camera);
    let (model, camera_frame) = match rig::first_info(log, &p.camera, &info_topic) {
        Ok(info) => {
            let frame = if info.header.frame_id.is_empty() {
                p.camera.clone()
            } else {
                info.header.frame_id.clone()
            };
            match info.model() {
                Ok(CameraModel::Paracatadioptric(m)) => (Some(m), frame),
                Ok(_) => anyhow::bail!("{file}: {info_topic} is not a paracatadioptric camera"),
                Err(e) => anyhow::bail!("{file}: {info_topic}: {e}"),
            }
        }
        Err(_) => (None, p.camera.clone()),
    };
    let mut ctx = Ctx {
        log,
        p,
        tf,
        gt,
        model,
        camera_frame,
        laser_frame: String::new(),
        tilt: Tilt::read(log, &p.imu_topic)?,
        t0: Nanos(0),
        tolerance_ns: (p.gt_tolerance_s * 1e9).round() as u64,
    };
    bar.set_message("replaying the trackers");
    let (tracks, truth_rows, m1, colour) = replay_all(&mut ctx, bar)?;
    let loop_rows = closed_loop::rows(&ctx.tf, log, &p.follower_topic, ctx.t0)?;
    let mut out = SessionTables::new();
    out.insert(tables::TRACKS.into(), TrackRow::frame(&tracks)?);
    out.insert(tables::TRUTH.into(), TruthRow::frame(&truth_rows)?);
    out.insert(tables::LOOP.into(), tables::LoopRow::frame(&loop_rows)?);
    out.insert(tables::METHOD1.into(), Method1Row::frame(&m1)?);
    out.insert(tables::REAL.into(), tables::RealRow::frame(&[])?);
    out.insert(tables::COLOUR.into(), ColourRow::frame(&colour)?);
    Ok(out)
}

/// The latest omni frame and the camera frames still to come.
struct Omni<'a> {
    frames: Option<camera_frames::CameraFrames<'a>>,
    next: Option<camera_frames::CameraFrame>,
    latest: Option<(Nanos, RgbImage)>,
    index: i64,
}

impl Omni<'_> {
    /// Advance to the last frame stamped at or before `t`, handing every frame passed to
    /// `on_frame` (index, stamp, image), oldest first.
    fn advance(
        &mut self,
        t: Nanos,
        on_frame: &mut dyn FnMut(i64, Nanos, &RgbImage) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let Some(frames) = self.frames.as_mut() else {
            return Ok(());
        };
        loop {
            if self.next.is_none() {
                self.next = frames.next().transpose()?;
            }
            match self.next.take() {
                Some(f) if f.stamp <= t => {
                    on_frame(self.index, f.stamp, &f.rgb)?;
                    self.index += 1;
                    self.latest = Some((f.stamp, f.rgb));
                }
                other => {
                    self.next = other;
                    return Ok(());
                }
            }
        }
    }
}

type Replayed = (
    Vec<TrackRow>,
    Vec<TruthRow>,
    Vec<Method1Row>,
    Vec<ColourRow>,
);

/// The one pass over scans and omni frames (see the module doc).
fn replay_all(ctx: &mut Ctx<'_>, bar: &dyn Progress) -> anyhow::Result<Replayed> {
    let p = ctx.p;
    let log = ctx.log;
    let options = LaserOptions {
        fixed_frame: Some(p.fixed_frame.clone()),
        ..LaserOptions::default()
    };
    let mut omni = Omni {
        frames: match camera_frames::image_topic(log, &p.camera) {
            Some(topic) if ctx.model.is_some() => Some(camera_frames::frames(log, &topic, None)?),
            _ => None,
        },
        next: None,
        latest: None,
        index: 0,
    };
    let mut method1 = match ctx.model.as_ref() {
        Some(m) => Some(method1::State::new(
            m,
            p,
            ctx.camera_frame.clone(),
            ctx.log.path(),
        )?),
        None => None,
    };
    let mut runners: Vec<(String, Runner)> = Vec::new();
    let (mut tracks, mut truth_rows, mut m1_rows) = (Vec::new(), Vec::new(), Vec::new());
    let mut colour = Vec::new();
    let mut prev_robot: Option<(f64, f64, f64)> = None;
    for (idx, f) in laser_frames::scans(log, &p.scan_topic, &options)?.enumerate() {
        let f = f?;
        if idx == 0 {
            ctx.t0 = f.stamp;
            ctx.laser_frame = f.frame.clone();
        }
        let t = ctx.t_s(f.stamp);
        let c: &Ctx<'_> = ctx;
        omni.advance(f.stamp, &mut |fi, stamp, img| {
            if let Some(m1) = method1.as_mut()
                && fi % p.method1_every as i64 == 0
            {
                let t_img = c.t_s(stamp);
                m1_rows.extend(m1.frame(&c.tf, &c.gt, c.tolerance_ns, (fi, stamp, t_img), img)?);
            }
            Ok(())
        })?;
        let Some(pose) = ctx.fixed_from(&f.frame, f.stamp) else {
            continue;
        };
        if runners.is_empty() {
            let Some(init) = initial_point(ctx, f.stamp) else {
                continue;
            };
            for name in &p.methods {
                let m = params::method(name).with_context(|| format!("unknown method {name}"))?;
                runners.push((name.clone(), Runner::new(m, p, init)));
            }
        }
        let truth_row = truth_at(ctx, &f, idx as i64, t, &mut prev_robot);
        let (rows, blobs) = step_all(ctx, &mut runners, &omni, &f, &pose, idx as i64, t)?;
        tracks.extend(rows);
        colour.extend(blobs);
        truth_rows.extend(truth_row);
        if idx % 50 == 0 {
            bar.set_message(&format!("scan {idx}"));
        }
    }
    Ok((tracks, truth_rows, m1_rows, colour))
}

/// The target's first true position moved into the fixed frame: where the robot's operator
/// pointed it (the closed loop starts the same way).
fn initial_point(ctx: &Ctx<'_>, at: Nanos) -> Option<[f64; 2]> {
    let frame = ctx.gt.nearest(at, ctx.tolerance_ns)?;
    let person = frame.people.iter().find(|q| q.id == ctx.p.target_id)?;
    let fixed_from_map = ctx.tf.lookup(&ctx.p.fixed_frame, "map", at).ok()?;
    let q = fixed_from_map * Point3::new(person.x, person.y, 0.0);
    Some([q.x, q.y])
}

/// Every method on one scan, their estimates in `map` and scored against the truth; the
/// paper configuration's blobs with their colour correlation and what they are.
fn step_all(
    ctx: &Ctx<'_>,
    runners: &mut [(String, Runner)],
    omni: &Omni<'_>,
    f: &LaserFrame,
    pose: &Isometry3<f64>,
    idx: i64,
    t: f64,
) -> anyhow::Result<(Vec<TrackRow>, Vec<ColourRow>)> {
    let g = ScanGeometry::of(&f.scan);
    let pts = points::project(&f.scan.ranges, &g, Some(pose));
    let camera_from_fixed = omni
        .latest
        .as_ref()
        .and_then(|(stamp, _)| ctx.fixed_from(&ctx.camera_frame, *stamp))
        .map(|c| c.inverse());
    let map_from_fixed = ctx.tf.lookup("map", &ctx.p.fixed_frame, f.stamp).ok();
    let people = ctx.gt.nearest(f.stamp, ctx.tolerance_ns);
    let mut rows = Vec::with_capacity(runners.len());
    let mut colour = Vec::new();
    for (name, r) in runners.iter_mut() {
        let obs = ScanObs {
            t,
            points: &pts,
            omni: replay::omni(
                omni.latest.as_ref().map(|(_, img)| img),
                camera_from_fixed,
                ctx.model.as_ref(),
            ),
            laser_pose: Some(pose),
        };
        let out = r
            .step(&obs, f.scan.ranges.len(), Some(pose))
            .with_context(|| format!("{}: {name} at scan {idx}", ctx.log.path().display()))?;
        if name == params::PAPER
            && let (Some(m), Some(frame)) = (map_from_fixed.as_ref(), people)
        {
            let target = frame.people.iter().find(|q| q.id == ctx.p.target_id);
            colour.extend(out.blob_corr.iter().map(|(c, corr)| {
                let q = m * Point3::new(c[0], c[1], 0.0);
                let (kind, offset) = blob_kind(frame, (q.x, q.y), ctx.p);
                ColourRow {
                    scan_idx: idx,
                    kind: kind.into(),
                    corr: *corr,
                    dx: offset.map(|o| o[0]),
                    dy: offset.map(|o| o[1]),
                    tdx: target.map(|t| q.x - t.x),
                    tdy: target.map(|t| q.y - t.y),
                }
            }));
        }
        rows.push(track_row(
            ctx,
            name,
            idx,
            t,
            &out,
            map_from_fixed.as_ref(),
            people,
        ));
    }
    Ok((rows, colour))
}

/// What a blob at `at` (map) is: the target, another person (within `lock_m` of their true
/// position) or something static; for a person's blob, its centre minus their position.
fn blob_kind(frame: &PeopleFrame, at: (f64, f64), p: &Params) -> (&'static str, Option<[f64; 2]>) {
    let near = frame
        .people
        .iter()
        .map(|q| (q.id, [at.0 - q.x, at.1 - q.y]))
        .filter(|(_, o)| o[0].hypot(o[1]) <= p.lock_m)
        .min_by(|a, b| a.1[0].hypot(a.1[1]).total_cmp(&b.1[0].hypot(b.1[1])));
    match near {
        Some((id, o)) if id == p.target_id => ("target", Some(o)),
        Some((_, o)) => ("person", Some(o)),
        None => ("static", None),
    }
}

fn track_row(
    ctx: &Ctx<'_>,
    method: &str,
    idx: i64,
    t: f64,
    out: &StepOutput,
    map_from_fixed: Option<&Isometry3<f64>>,
    people: Option<&PeopleFrame>,
) -> TrackRow {
    let est = out.estimate.as_ref().zip(map_from_fixed).map(|(e, m)| {
        let q = m * Point3::new(e.position[0], e.position[1], 0.0);
        let v = m.rotation * nalgebra::Vector3::new(e.velocity[0], e.velocity[1], 0.0);
        (q.x, q.y, v.x, v.y, e.covariance_norm)
    });
    let (mut target_err, mut nearest) = (None, None);
    if let (Some((x, y, ..)), Some(frame)) = (est, people) {
        let d = |q: &crate::groundtruth::PersonTruth| (q.x - x).hypot(q.y - y);
        target_err = frame.people.iter().find(|q| q.id == ctx.p.target_id).map(d);
        nearest = frame
            .people
            .iter()
            .map(|q| (i64::from(q.id), d(q)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
    }
    TrackRow {
        method: method.to_string(),
        scan_idx: idx,
        t_s: t,
        x: est.map(|e| e.0),
        y: est.map(|e| e.1),
        vx: est.map(|e| e.2),
        vy: est.map(|e| e.3),
        cov_norm: est.map(|e| e.4),
        reset: out.reset,
        initialised: out.initialised,
        blobs: out.blobs as i64,
        gated: out.gated as i64,
        beta0: out.beta0,
        lr: out.chosen_lr,
        corr: out.chosen_corr,
        target_err_m: target_err,
        nearest_id: nearest.map(|n| n.0),
        nearest_m: nearest.map(|n| n.1),
    }
}

/// The ground truth at a scan (see [`TruthRow`]); `None` without the robot's true pose.
fn truth_at(
    ctx: &Ctx<'_>,
    f: &LaserFrame,
    idx: i64,
    t: f64,
    prev: &mut Option<(f64, f64, f64)>,
) -> Option<TruthRow> {
    let base = ctx.map_from("base_link", f.stamp)?;
    let laser = ctx.map_from(&ctx.laser_frame, f.stamp)?;
    let (yaw, pitch) = scene::yaw_pitch(&base);
    let (x, y) = (base.translation.vector.x, base.translation.vector.y);
    let v = match *prev {
        Some((t0, x0, y0)) if t > t0 => (x - x0).hypot(y - y0) / (t - t0),
        _ => 0.0,
    };
    *prev = Some((t, x, y));
    let frame = ctx.gt.nearest(f.stamp, ctx.tolerance_ns);
    let target = frame.and_then(|fr| fr.people.iter().find(|q| q.id == ctx.p.target_id));
    let (mut ground, mut occluded, mut out_of_view, mut obstacle) = (false, false, true, false);
    if let (Some(tg), Some(fr)) = (target, frame) {
        let others: Vec<_> = fr.people.iter().filter(|q| q.id != tg.id).collect();
        let fov = 0.5 * (f64::from(f.scan.angle_max) - f64::from(f.scan.angle_min)).abs();
        (ground, occluded, out_of_view) = scene::view(
            &laser,
            tg,
            &others,
            fov,
            f64::from(f.scan.range_max),
            ctx.p.occlusion_margin_m,
        );
        let beams = scene::Beams {
            angle_min: f64::from(f.scan.angle_min),
            increment: f64::from(f.scan.angle_increment),
            ranges: &f.scan.ranges,
        };
        obstacle = !ground
            && !occluded
            && !out_of_view
            && scene::short_of(&laser, tg, beams, ctx.p.occlusion_margin_m);
    }
    let rb = target.map(|tg| scene::range_bearing(x, y, yaw, (tg.x, tg.y)));
    Some(TruthRow {
        scan_idx: idx,
        t_s: t,
        robot_x: x,
        robot_y: y,
        robot_yaw: yaw,
        robot_v: v,
        pitch,
        target_x: target.map(|q| q.x),
        target_y: target.map(|q| q.y),
        target_vx: target.map(|q| q.vx),
        target_vy: target.map(|q| q.vy),
        range_m: rb.map(|r| r.0),
        bearing_rad: rb.map(|r| r.1),
        ground,
        occluded,
        out_of_view,
        obstacle,
    })
}
