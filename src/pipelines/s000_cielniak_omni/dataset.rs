//! The aggregation's data: every session's tables read back, the hat sightings, and the frames
//! usable for the appearance model (omni features with a position from the measurement system).

use std::collections::BTreeMap;

use anyhow::Context;

use super::tables::{self, HatRow, OmniRow, PoseRow, SkipRow, TargetRow, TruthRow};
use crate::calib::external::{self, BearingCamera};
use crate::run::Aggregate;

/// Cameras that see the whole hat, with its column, per (session, stamp).
pub type Sightings = BTreeMap<(usize, i64), Vec<(usize, f64)>>;

/// The per-session tables of all sessions, each row with its session index.
pub struct Inputs {
    pub omni: Vec<(usize, OmniRow)>,
    pub targets: Vec<(usize, TargetRow)>,
    pub truth: Vec<(usize, TruthRow)>,
    pub seen: Sightings,
    /// The omni camera's pose (first session's).
    pub pose: PoseRow,
    pub sessions: usize,
}

impl Inputs {
    pub fn read(ctx: &Aggregate) -> anyhow::Result<Inputs> {
        let pose = tables::first::<PoseRow>(ctx, "omni_pose")?
            .first()
            .copied()
            .context("no omni pose")?;
        Ok(Inputs {
            omni: tables::all(ctx, "omni")?,
            targets: tables::all(ctx, "targets")?,
            truth: tables::all(ctx, "truth")?,
            seen: sightings(&tables::all::<HatRow>(ctx, "hats")?),
            pose,
            sessions: ctx.sessions.len(),
        })
    }
}

/// A summary line on the messages the frames layer skipped in all sessions (none if none).
pub fn skipped_summary(ctx: &Aggregate) -> anyhow::Result<Option<String>> {
    let rows: Vec<(usize, SkipRow)> = tables::all(ctx, "skips")?;
    Ok(skipped_line(&rows))
}

/// "N bad messages skipped (topic: n, …); first: <error>", topics merged over sessions.
pub fn skipped_line(rows: &[(usize, SkipRow)]) -> Option<String> {
    let first = rows.first()?;
    let mut by_topic: BTreeMap<&str, i64> = BTreeMap::new();
    for (_, r) in rows {
        *by_topic.entry(r.topic.as_str()).or_default() += r.count;
    }
    let total: i64 = by_topic.values().sum();
    let topics: Vec<String> = by_topic.iter().map(|(t, n)| format!("{t}: {n}")).collect();
    Some(format!(
        "{total} bad messages skipped ({}); first: {}",
        topics.join(", "),
        first.1.first_error
    ))
}

/// Group the whole-hat detections by (session, stamp), in table order within a group.
pub fn sightings(hats: &[(usize, HatRow)]) -> Sightings {
    let mut seen = Sightings::new();
    for (s, h) in hats.iter().filter(|(_, h)| h.whole) {
        seen.entry((*s, h.stamp))
            .or_default()
            .push((h.camera as usize, h.u));
    }
    seen
}

/// One frame usable for the appearance model.
#[derive(Debug, Clone, Copy)]
pub struct Row {
    pub session: usize,
    pub stamp: i64,
    pub features: [f64; 3],
    /// Distance and bearing from the measurement system.
    pub distance: f64,
    pub bearing: f64,
    /// Bearing measured in the panorama (map frame).
    pub omni_bearing: f64,
    pub ext: (f64, f64),
    pub cam: (f64, f64),
    pub person: i64,
    pub truth: Option<(f64, f64)>,
}

/// The appearance model's frames, sorted by (session, stamp), and the measurement system's
/// errors against the simulator's truth (on every measured frame, with a person or not).
pub struct Dataset {
    pub rows: Vec<Row>,
    pub ext_err_truth: Vec<f64>,
    pub cam_xy: (f64, f64),
    pub cam_yaw: f64,
}

impl Dataset {
    /// Feature vectors, one per row.
    pub fn xs(&self) -> Vec<Vec<f64>> {
        self.rows.iter().map(|r| r.features.to_vec()).collect()
    }

    /// Distances from the measurement system, one per row.
    pub fn distances(&self) -> Vec<f64> {
        self.rows.iter().map(|r| r.distance).collect()
    }
}

/// Without ground-truth ids, the person is 1 in the first half of the session and 2 after.
pub fn person(truth_id: Option<i64>, stamp: i64, first: i64, last: i64) -> i64 {
    match truth_id {
        Some(id) => id,
        None if stamp < (first + last) / 2 => 1,
        None => 2,
    }
}

/// Locate the person with the calibrated cameras on every omni frame and keep the frames that
/// also have features; at least 20 are needed.
pub fn build(
    inputs: &Inputs,
    cams: &[BearingCamera],
    background_frames: usize,
) -> anyhow::Result<Dataset> {
    let cam_xy = (inputs.pose.x, inputs.pose.y);
    let cam_yaw = inputs.pose.yaw;
    let mut truth_at: BTreeMap<(usize, i64), (i64, f64, f64)> = BTreeMap::new();
    for (s, t) in &inputs.truth {
        truth_at.entry((*s, t.stamp)).or_insert((t.id, t.x, t.y));
    }
    let mut first_stamp = vec![i64::MAX; inputs.sessions];
    let mut last_stamp = vec![i64::MIN; inputs.sessions];
    for (s, o) in &inputs.omni {
        first_stamp[*s] = first_stamp[*s].min(o.stamp);
        last_stamp[*s] = last_stamp[*s].max(o.stamp);
    }
    let mut rows: Vec<Row> = Vec::new();
    let mut ext_err_truth = Vec::new();
    for (s, o) in &inputs.omni {
        let Some(ext) = inputs
            .seen
            .get(&(*s, o.stamp))
            .filter(|v| v.len() >= 2)
            .and_then(|v| external::locate(cams, v))
        else {
            continue;
        };
        let tr = truth_at.get(&(*s, o.stamp));
        if let Some((_, x, y)) = tr {
            ext_err_truth.push((ext.0 - x).hypot(ext.1 - y));
        }
        if !o.valid {
            continue;
        }
        let (dx, dy) = (ext.0 - cam_xy.0, ext.1 - cam_xy.1);
        rows.push(Row {
            session: *s,
            stamp: o.stamp,
            features: [o.width, o.apparent_distance, o.pixels],
            distance: dx.hypot(dy),
            bearing: dy.atan2(dx),
            omni_bearing: external::wrap(cam_yaw + o.angle),
            ext,
            cam: cam_xy,
            person: person(tr.map(|t| t.0), o.stamp, first_stamp[*s], last_stamp[*s]),
            truth: tr.map(|(_, x, y)| (*x, *y)),
        });
    }
    if rows.len() < 20 {
        let with_person = inputs.omni.iter().filter(|(_, o)| o.valid).count();
        let measured = inputs.seen.values().filter(|v| v.len() >= 2).count();
        anyhow::bail!(
            "only {} frames have both omni features and a measured position; need at least 20 \
             ({with_person} of {} omni frames show a person, {measured} webcam frames see the hat in ≥ 2 cameras; \
             no person in any omni frame usually means one stood in the first params.background_frames = {} frames, \
             which are taken as the empty background, or that params.panorama / params.inner_radius do not fit the mirror)",
            rows.len(),
            inputs.omni.len(),
            background_frames
        );
    }
    rows.sort_by_key(|r| (r.session, r.stamp));
    Ok(Dataset {
        rows,
        ext_err_truth,
        cam_xy,
        cam_yaw,
    })
}

/// A frame of a person at `stamp` with features `f` (tests).
#[cfg(test)]
pub fn test_row(session: usize, stamp: i64, person: i64, f: [f64; 3]) -> Row {
    Row {
        session,
        stamp,
        features: f,
        distance: f[1],
        bearing: 0.0,
        omni_bearing: 0.0,
        ext: (0.0, 0.0),
        cam: (0.0, 0.0),
        person,
        truth: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hat(stamp: i64, camera: i64, u: f64, whole: bool) -> HatRow {
        HatRow {
            stamp,
            camera,
            u,
            v: 0.0,
            area: 10,
            whole,
        }
    }

    #[test]
    fn sightings_keep_whole_hats_grouped_by_session_and_stamp() {
        let hats = [
            (0, hat(5, 0, 10.0, true)),
            (0, hat(5, 1, 20.0, true)),
            (0, hat(5, 2, 30.0, false)),
            (1, hat(5, 3, 40.0, true)),
            (0, hat(6, 2, 50.0, false)),
        ];
        let seen = sightings(&hats);
        assert_eq!(seen.len(), 2);
        assert_eq!(seen[&(0, 5)], [(0, 10.0), (1, 20.0)]);
        assert_eq!(seen[&(1, 5)], [(3, 40.0)]);
    }

    #[test]
    fn skipped_messages_are_summed_per_topic_over_sessions() {
        let row = |topic: &str, count, e: &str| SkipRow {
            topic: topic.into(),
            count,
            first_error: e.into(),
        };
        assert_eq!(skipped_line(&[]), None);
        let rows = [
            (0, row("/cam_0/image_raw", 2, "bad jpeg")),
            (1, row("/cam_0/image_raw", 1, "other")),
            (1, row("/a", 4, "x")),
        ];
        assert_eq!(
            skipped_line(&rows).as_deref(),
            Some("7 bad messages skipped (/a: 4, /cam_0/image_raw: 3); first: bad jpeg")
        );
    }

    #[test]
    fn without_truth_the_person_is_the_half_of_the_session() {
        assert_eq!(person(Some(7), 0, 0, 100), 7);
        assert_eq!(person(None, 49, 0, 100), 1);
        assert_eq!(person(None, 50, 0, 100), 2);
        assert_eq!(person(None, 100, 0, 100), 2);
    }
}
