//! Multi mode's filters and scores (our addition): every session's cached leg pairs and head
//! tops through [`crate::track::height_tracks::MultiTracker`] in three configurations —
//! laser only, laser + the first camera, laser + every camera (each camera's head-top
//! bearing + elevation is its own EKF update, from that camera's TF pose) — then scored
//! against every person's ground truth: CLEAR MOT / IDF1 on the floor ([`crate::eval::mot`],
//! Euclidean, `mot_max_m`), the matched distance per person and stamp, and each person's
//! height at the end (the height of the track matched to the person at the last stamp it
//! was matched).

use std::collections::BTreeMap;

use super::params::Params;
use super::tables::{self, CameraObsRow, LaserObsRow, PersonRow};
use crate::eval::mot::{self, Evaluation, EventKind, Geometry, GroundPoint, MatchRule};
use crate::run::Aggregate;
use crate::track::height_ekf::SensorAt;
use crate::track::height_tracks::{MultiTracker, Observation};

/// One session's cached observations and truth.
pub struct MultiSession {
    pub name: String,
    pub laser: Vec<LaserObsRow>,
    /// Per camera of `cameras`, in order.
    pub cameras: Vec<Vec<CameraObsRow>>,
    pub truth: Vec<PersonRow>,
}

/// Read every evaluated session (the skin-training log is left out).
pub fn load(ctx: &Aggregate, p: &Params) -> anyhow::Result<Vec<MultiSession>> {
    let mut out = Vec::new();
    for (info, t) in ctx.sessions {
        if p.is_training(&info.path) {
            continue;
        }
        let n = &info.name;
        let mut cameras = Vec::new();
        for cam in &p.cameras {
            cameras.push(tables::read(t, &tables::camera_table(cam), n)?);
        }
        out.push(MultiSession {
            name: n.clone(),
            laser: tables::read(t, tables::LASER, n)?,
            cameras,
            truth: tables::read(t, tables::PEOPLE_TRUTH, n)?,
        });
    }
    Ok(out)
}

/// A sensor configuration: which cameras (indices into `cameras`) join the laser.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub name: String,
    pub cameras: Vec<usize>,
}

/// Laser only, laser + the first camera, laser + every camera (when there are two or more).
pub fn configs(p: &Params) -> Vec<Config> {
    let mut out = vec![Config {
        name: "laser only".into(),
        cameras: vec![],
    }];
    if let Some(first) = p.cameras.first() {
        out.push(Config {
            name: format!("laser+{first}"),
            cameras: vec![0],
        });
    }
    if p.cameras.len() > 1 {
        out.push(Config {
            name: format!("laser+{}", p.cameras.join("+")),
            cameras: (0..p.cameras.len()).collect(),
        });
    }
    out
}

/// A reported (confirmed) track's state after an event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackState {
    pub id: u64,
    pub x: f64,
    pub y: f64,
    pub h: f64,
    pub sigma_h: f64,
}

/// The reported tracks after one sensor event.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    pub stamp_ns: i64,
    pub tracks: Vec<TrackState>,
}

/// One configuration's run over a session.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrackRun {
    pub snapshots: Vec<Snapshot>,
    /// Tracks started (confirmed or not).
    pub born: usize,
    pub laser_assigned: usize,
    pub camera_assigned: usize,
    pub camera_unassigned: usize,
}

fn seconds(ns: i64) -> f64 {
    ns as f64 * 1e-9
}

/// One sensor event: its stamp, its sort key (laser first, then the cameras in order) and
/// its observations.
type Event = (i64, usize, i64, Vec<Observation>);

fn laser_events(laser: &[LaserObsRow]) -> Vec<Event> {
    let mut out: Vec<Event> = Vec::new();
    for r in laser {
        let o = Observation::Laser {
            range_m: r.range_m,
            bearing_rad: r.bearing_rad,
            laser: SensorAt {
                x: r.laser_x,
                y: r.laser_y,
                z: 0.0,
                yaw: r.laser_yaw,
            },
        };
        match out.last_mut() {
            Some(e) if e.2 == r.scan_idx => e.3.push(o),
            _ => out.push((r.stamp_ns, 0, r.scan_idx, vec![o])),
        }
    }
    out
}

fn camera_events(rows: &[CameraObsRow], key: usize) -> Vec<Event> {
    let mut out: Vec<Event> = Vec::new();
    for r in rows {
        let o = Observation::Camera {
            bearing_rad: r.bearing_rad,
            elevation_rad: r.elevation_rad,
            camera: SensorAt {
                x: r.cam_x,
                y: r.cam_y,
                z: r.cam_z,
                yaw: 0.0,
            },
        };
        match out.last_mut() {
            Some(e) if e.2 == r.frame_idx => e.3.push(o),
            _ => out.push((r.stamp_ns, key, r.frame_idx, vec![o])),
        }
    }
    out
}

/// Run configuration `c` over session `s`: births from leg pairs only.
pub fn track(s: &MultiSession, p: &Params, c: &Config) -> TrackRun {
    let mut events = laser_events(&s.laser);
    for &k in &c.cameras {
        if let Some(rows) = s.cameras.get(k) {
            events.extend(camera_events(rows, k + 1));
        }
    }
    events.sort_by_key(|e| (e.0, e.1, e.2));
    let mut m = MultiTracker::new(p.tracker());
    let mut out = TrackRun::default();
    for (t, key, _, obs) in &events {
        let is_laser = *key == 0;
        let r = m.step(seconds(*t), obs, is_laser);
        out.born += r.born.len();
        if is_laser {
            out.laser_assigned += r.assigned.len();
        } else {
            out.camera_assigned += r.assigned.len();
            out.camera_unassigned += r.unassigned.len();
        }
        let tracks = m
            .tracks()
            .iter()
            .filter(|t| m.confirmed(t))
            .map(|t| TrackState {
                id: t.id,
                x: t.ekf.xy()[0],
                y: t.ekf.xy()[1],
                h: t.ekf.height(),
                sigma_h: t.ekf.sigma_height(),
            })
            .collect();
        out.snapshots.push(Snapshot {
            stamp_ns: *t,
            tracks,
        });
    }
    out
}

/// A person's height at the end, from the track last matched to them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PersonHeight {
    pub id: i64,
    pub truth_m: f64,
    pub final_m: Option<f64>,
    pub sigma_m: Option<f64>,
    /// Ground-truth stamps at which the person was matched to a track.
    pub matched: usize,
}

/// A run scored against the truth.
#[derive(Debug, Clone)]
pub struct Scored {
    pub eval: Evaluation,
    /// Matched floor distance (m) by (truth stamp, person id).
    pub errors: BTreeMap<(i64, i64), f64>,
    pub heights: Vec<PersonHeight>,
    /// Distinct reported track ids.
    pub tracks: usize,
}

fn point(frame: i64, id: i64, x: f64, y: f64) -> mot::Observation {
    mot::Observation {
        frame,
        id,
        geometry: Geometry::Point(GroundPoint { x_m: x, y_m: y }),
        confidence: 1.0,
    }
}

/// Score `run` at every ground-truth stamp with the latest snapshot at or before it.
pub fn score(s: &MultiSession, run: &TrackRun, p: &Params) -> anyhow::Result<Scored> {
    let stamps: Vec<i64> = run.snapshots.iter().map(|x| x.stamp_ns).collect();
    let snapshot_at = |t: i64| {
        stamps
            .partition_point(|&x| x <= t)
            .checked_sub(1)
            .map(|k| &run.snapshots[k])
    };
    let gt: Vec<mot::Observation> = s
        .truth
        .iter()
        .map(|r| point(r.stamp_ns, r.id, r.x, r.y))
        .collect();
    let mut frames: Vec<i64> = s.truth.iter().map(|r| r.stamp_ns).collect();
    frames.dedup();
    let mut hyp = Vec::new();
    let mut ids = std::collections::BTreeSet::new();
    for &f in &frames {
        for t in snapshot_at(f).map_or(&[][..], |x| &x.tracks[..]) {
            hyp.push(point(f, t.id as i64, t.x, t.y));
            ids.insert(t.id);
        }
    }
    let eval = mot::evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: p.mot_max_m })
        .map_err(|e| anyhow::anyhow!("{}: scoring the tracks: {e}", s.name))?;
    let mut errors = BTreeMap::new();
    let mut last: BTreeMap<i64, (i64, i64)> = BTreeMap::new();
    let mut matched: BTreeMap<i64, usize> = BTreeMap::new();
    for e in &eval.events {
        if !matches!(e.kind, EventKind::Match | EventKind::Switch) {
            continue;
        }
        let (Some(g), Some(h), Some(d)) = (e.gt_id, e.hyp_id, e.distance) else {
            continue;
        };
        errors.insert((e.frame, g), d);
        last.insert(g, (e.frame, h));
        *matched.entry(g).or_default() += 1;
    }
    let mut truth_h: BTreeMap<i64, f64> = BTreeMap::new();
    for r in &s.truth {
        truth_h.entry(r.id).or_insert(r.height_m);
    }
    let heights = truth_h
        .iter()
        .map(|(&id, &truth_m)| {
            let state = last.get(&id).and_then(|&(frame, h)| {
                snapshot_at(frame)?
                    .tracks
                    .iter()
                    .find(|t| t.id as i64 == h)
                    .copied()
            });
            PersonHeight {
                id,
                truth_m,
                final_m: state.map(|t| t.h),
                sigma_m: state.map(|t| t.sigma_h),
                matched: matched.get(&id).copied().unwrap_or(0),
            }
        })
        .collect();
    Ok(Scored {
        eval,
        errors,
        heights,
        tracks: ids.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn laser_row(scan: i64, t: i64, x: f64, y: f64) -> LaserObsRow {
        // laser at the origin facing +x
        LaserObsRow {
            scan_idx: scan,
            stamp_ns: t,
            range_m: x.hypot(y),
            bearing_rad: y.atan2(x),
            laser_x: 0.0,
            laser_y: 0.0,
            laser_yaw: 0.0,
        }
    }

    #[test]
    fn two_people_seen_by_the_laser_score_a_perfect_mota_and_their_truth_heights_are_kept() {
        // persons 7 (2, 1) and 9 (4, −1) standing; one scan and one truth stamp every 0.2 s
        let mut laser = Vec::new();
        let mut truth = Vec::new();
        for k in 0..20i64 {
            let t = k * 200_000_000;
            laser.push(laser_row(k, t, 2.0, 1.0));
            laser.push(laser_row(k, t, 4.0, -1.0));
            for (id, x, y, h) in [(7, 2.0, 1.0, 1.84), (9, 4.0, -1.0, 1.62)] {
                truth.push(PersonRow {
                    stamp_ns: t,
                    id,
                    x,
                    y,
                    height_m: h,
                });
            }
        }
        let s = MultiSession {
            name: "hand-made".into(),
            laser,
            cameras: vec![],
            truth,
        };
        let p = Params::default();
        let c = &configs(&p)[0];
        assert_eq!(c.name, "laser only");
        let run = track(&s, &p, c);
        assert_eq!(run.born, 2);
        let sc = score(&s, &run, &p).expect("scores");
        let m = &sc.eval.metrics.clear;
        // reported from the third scan on (confirm_hits = 3): two misses each before that
        assert_eq!(m.num_misses, 4);
        assert_eq!((m.num_false_positives, m.num_switches), (0, 0));
        assert!((m.mota - (1.0 - 4.0 / 40.0)).abs() < 1e-12, "{}", m.mota);
        assert!(m.motp < 1e-6, "noise-free: {}", m.motp);
        assert_eq!(sc.tracks, 2);
        let ids: Vec<i64> = sc.heights.iter().map(|h| h.id).collect();
        assert_eq!(ids, vec![7, 9]);
        assert_eq!(sc.heights[0].truth_m, 1.84);
        assert_eq!(sc.heights[0].matched, 18);
        // the laser alone never learns a height: the prior h0 stays
        assert!((sc.heights[0].final_m.expect("matched") - p.h0_m).abs() < 1e-9);
    }
}
