//! Local tracks ([`LocalTracker`]) on every session: GMM blobs tracked frame to frame and
//! handed over to the EM-like colour tracker when the camera moves or the person stands
//! still; per session the tracks and the ground-truth boxes, scored per dataset with CLEAR
//! MOT and IDF1 (IoU ≥ `local_eval.min_iou`) in the `local_tracks` table.

use polars::prelude::*;

use super::params::{LocalEvalParams, Params};
use super::shared::{Frame, SessionRow, by_dataset, session_row};
use crate::eval::mot::{self, BoxPx, Geometry, MatchRule, Metrics};
use crate::report::Table;
use crate::report::columns::bools;
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products, SessionTables};
use crate::table_row;
use crate::vision::local::{HandOver, LocalTracker, Mode};

pub(super) const TRACKS_TABLE: &str = "tracks";
pub(super) const GT_TABLE: &str = "gt_boxes";
pub(super) const HAS_GT_TABLE: &str = "has_ground_truth";

table_row! {
    /// Cached per session: one track's observation in one frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct TrackRow {
        pub frame: i64,
        pub t_s: f64,
        pub track: i64,
        pub mode: String,
        pub cx: f64,
        pub cy: f64,
        pub x0: f64,
        pub y0: f64,
        pub x1: f64,
        pub y1: f64,
        pub area_px: i64,
        pub similarity: Option<f64>,
        pub iterations: Option<i64>,
        pub camera_moving: bool,
    }
}

table_row! {
    /// Cached per session: a ground-truth person's box in one frame (right and bottom
    /// exclusive), people less visible than `local_eval.min_visibility` left out.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct GtBoxRow {
        pub frame: i64,
        pub id: i64,
        pub x0: f64,
        pub y0: f64,
        pub x1: f64,
        pub y1: f64,
        pub visibility: f64,
    }
}

table_row! {
    /// A row of the `local_tracks` table.
    #[derive(Debug, Clone, PartialEq)]
    struct LocalTracksRow {
        dataset: String,
        sessions: i64,
        frames: i64,
        camera_moving_frames: i64,
        tracks: i64,
        observations: i64,
        colour_camera_moving: i64,
        colour_standing_still: i64,
        handovers_camera: i64,
        handovers_still: i64,
        reacquired: i64,
        mota: Option<f64>,
        motp: Option<f64>,
        idf1: Option<f64>,
        id_switches: Option<i64>,
        false_positives: Option<i64>,
        misses: Option<i64>,
        recall: Option<f64>,
        precision: Option<f64>,
    }
}

/// A person's identity in the local-track evaluation: id and height (mm), so two people that
/// share an id in a log stay apart.
fn person_key(id: u32, height_m: f64) -> i64 {
    i64::from(id) * 100_000 + (height_m * 1000.0).round().clamp(0.0, 99_999.0) as i64
}

/// The local tracker of one session and what it records.
pub(super) struct LocalRun {
    tracker: LocalTracker,
    camera: String,
    min_visibility: f64,
    tracks: Vec<TrackRow>,
    gt: Vec<GtBoxRow>,
    moving_frames: i64,
}

impl LocalRun {
    pub fn new(p: &Params) -> anyhow::Result<Self> {
        Ok(Self {
            tracker: LocalTracker::new(p.local)?,
            camera: p.camera.clone(),
            min_visibility: p.local_eval.min_visibility,
            tracks: Vec::new(),
            gt: Vec::new(),
            moving_frames: 0,
        })
    }

    pub fn step(&mut self, f: &Frame) -> anyhow::Result<()> {
        for person in f.truth.iter().flat_map(|fr| &fr.people) {
            for v in person.cameras.iter().filter(|v| v.camera == self.camera) {
                if let Some(b) = v.bbox
                    && v.visibility >= self.min_visibility
                {
                    self.gt.push(GtBoxRow {
                        frame: f.index,
                        id: person_key(person.id, person.height),
                        x0: b[0],
                        y0: b[1],
                        // the ground truth's box is already right and bottom exclusive
                        x1: b[2],
                        y1: b[3],
                        visibility: v.visibility,
                    });
                }
            }
        }
        self.moving_frames += i64::from(f.moving);
        for o in self.tracker.step(f.view, f.moving)? {
            self.tracks.push(TrackRow {
                frame: f.index,
                t_s: f.t_s,
                track: i64::from(o.track),
                mode: o.mode.name().to_string(),
                cx: o.region.center.x,
                cy: o.region.center.y,
                x0: o.bbox[0],
                y0: o.bbox[1],
                x1: o.bbox[2],
                y1: o.bbox[3],
                area_px: o.area_px as i64,
                similarity: o.similarity,
                iterations: o.iterations.map(i64::from),
                camera_moving: f.moving,
            });
        }
        Ok(())
    }

    /// The tracker's foreground of the latest frame stepped (`None`: it took no blobs).
    pub fn foreground(&self) -> Option<&[u8]> {
        self.tracker.foreground()
    }

    /// The tracks' boxes of frame `frame` (the latest frame stepped).
    pub fn frame_tracks(&self, frame: i64) -> &[TrackRow] {
        let first = self
            .tracks
            .iter()
            .rposition(|t| t.frame != frame)
            .map_or(0, |i| i + 1);
        &self.tracks[first..]
    }

    /// The cached `tracks`, `gt_boxes` and `has_ground_truth` tables; the tracker's counters
    /// go to the session row.
    pub fn finish(
        self,
        has_ground_truth: bool,
        row: &mut SessionRow,
        out: &mut SessionTables,
    ) -> anyhow::Result<()> {
        let st = self.tracker.stats();
        row.moving_frames = self.moving_frames;
        row.gmm_restarts = st.gmm_restarts as i64;
        row.tracks_started = st.tracks_started as i64;
        row.handovers_camera = st.handovers_camera as i64;
        row.handovers_still = st.handovers_still as i64;
        row.reacquired = st.reacquired as i64;
        out.insert(TRACKS_TABLE.into(), TrackRow::frame(&self.tracks)?);
        out.insert(GT_TABLE.into(), GtBoxRow::frame(&self.gt)?);
        out.insert(HAS_GT_TABLE.into(), df! { "value" => [has_ground_truth] }?);
        Ok(())
    }
}

fn observation(frame: i64, id: i64, x0: f64, y0: f64, x1: f64, y1: f64) -> mot::Observation {
    mot::Observation {
        frame,
        id,
        geometry: Geometry::Box(BoxPx {
            left_px: x0,
            top_px: y0,
            width_px: x1 - x0,
            height_px: y1 - y0,
        }),
        confidence: 1.0,
    }
}

/// One dataset's row: the sessions' counters summed, the observations by mode, and CLEAR MOT
/// / IDF1 over the sessions with ground truth.
fn dataset_row(
    dataset: &str,
    sessions: &[&SessionTables],
    p: &LocalEvalParams,
) -> anyhow::Result<(LocalTracksRow, Option<Metrics>)> {
    let rule = MatchRule::Iou { min_iou: p.min_iou };
    let moving_name = Mode::Colour(HandOver::CameraMoving).name();
    let still_name = Mode::Colour(HandOver::StandingStill).name();
    let mut metrics: Vec<Metrics> = Vec::new();
    let mut row = LocalTracksRow {
        dataset: dataset.to_string(),
        sessions: sessions.len() as i64,
        frames: 0,
        camera_moving_frames: 0,
        tracks: 0,
        observations: 0,
        colour_camera_moving: 0,
        colour_standing_still: 0,
        handovers_camera: 0,
        handovers_still: 0,
        reacquired: 0,
        mota: None,
        motp: None,
        idf1: None,
        id_switches: None,
        false_positives: None,
        misses: None,
        recall: None,
        precision: None,
    };
    for f in sessions {
        let s = session_row(f);
        row.frames += s.frames;
        row.camera_moving_frames += s.moving_frames;
        row.tracks += s.tracks_started;
        row.handovers_camera += s.handovers_camera;
        row.handovers_still += s.handovers_still;
        row.reacquired += s.reacquired;
        let Some(t) = f.get(TRACKS_TABLE) else {
            continue;
        };
        let tracks = TrackRow::read(t)?;
        row.observations += tracks.len() as i64;
        row.colour_camera_moving += tracks.iter().filter(|o| o.mode == moving_name).count() as i64;
        row.colour_standing_still += tracks.iter().filter(|o| o.mode == still_name).count() as i64;
        let has_gt = f
            .get(HAS_GT_TABLE)
            .and_then(|d| bools(d, "value").ok()?.first().copied())
            .unwrap_or(false);
        if let (true, Some(g)) = (has_gt, f.get(GT_TABLE)) {
            let truth: Vec<mot::Observation> = GtBoxRow::read(g)?
                .iter()
                .map(|b| observation(b.frame, b.id, b.x0, b.y0, b.x1, b.y1))
                .collect();
            let hyp: Vec<mot::Observation> = tracks
                .iter()
                .map(|o| observation(o.frame, o.track, o.x0, o.y0, o.x1, o.y1))
                .collect();
            metrics.push(mot::evaluate(&truth, &hyp, rule)?.metrics);
        }
    }
    let m = (!metrics.is_empty()).then(|| Metrics::overall(&metrics));
    if let Some(m) = &m {
        row.mota = Some(m.clear.mota);
        row.motp = Some(m.clear.motp);
        row.idf1 = Some(m.identity.idf1);
        row.id_switches = Some(m.clear.num_switches as i64);
        row.false_positives = Some(m.clear.num_false_positives as i64);
        row.misses = Some(m.clear.num_misses as i64);
        row.recall = Some(m.clear.recall);
        row.precision = Some(m.clear.precision);
    }
    Ok((row, m))
}

/// The `local_tracks` table and a summary line per dataset with ground truth.
pub(super) fn products(ctx: &Aggregate, p: &Params, products: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for (dataset, sessions) in by_dataset(ctx) {
        let (row, m) = dataset_row(&dataset, &sessions, &p.local_eval)?;
        if let Some(m) = &m {
            products.summary.push(format!(
                "{dataset}: local tracks MOTA {:.3}, IDF1 {:.3}, {} ID switches; {} of {} observations from the colour tracker.",
                m.clear.mota,
                m.identity.idf1,
                m.clear.num_switches,
                row.colour_camera_moving + row.colour_standing_still,
                row.observations
            ));
        }
        rows.push(row);
    }
    products.tables.push(
        Table::new(
            "local_tracks",
            "Local tracks (GMM blobs, hand-over to the EM-like colour tracker) against the ground-truth boxes",
            LocalTracksRow::frame(&rows)?,
        )
        .with_precision("mota", 3)
        .with_precision("motp", 3)
        .with_precision("idf1", 3)
        .with_precision("recall", 3)
        .with_precision("precision", 3)
        .with_note(format!(
            "CLEAR MOT and IDF1 with boxes, a match needs IoU ≥ {} (MOTP = mean 1 − IoU); ground truth = every person with visibility ≥ {} in the camera. Blob boxes are the blobs' pixel bounds; colour-tracked boxes the √3σ box of the ellipse.",
            p.local_eval.min_iou, p.local_eval.min_visibility
        ))
        .with_note(format!(
            "The camera is taken as moving when odometry reports more than {} m/s or {} rad/s (mean twist over the last {} s of samples) and TF hangs the camera frame below the odometry's robot frame (a camera fixed in the world never moves); then the background model is paused and restarted ({} warm-up frames without blobs) when the camera stops, not learning the body boxes of the people tracked through the motion until they leave (at most {} frames).",
            p.local_eval.moving_speed_mps, p.local_eval.moving_turn_rad_s, p.local_eval.moving_window_s, p.local.warmup_frames, p.local.protect_frames
        ))
        .with_note("No paper values: Zajdel et al. (ICRA 2005) evaluate identities across local tracks, not the local tracks themselves."),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::rows::Rows;
    use crate::run::SessionTables;

    fn track(frame: i64, id: i64, x0: f64, mode: Mode) -> TrackRow {
        TrackRow {
            frame,
            t_s: 0.0,
            track: id,
            mode: mode.name().to_string(),
            cx: x0 + 5.0,
            cy: 10.0,
            x0,
            y0: 0.0,
            x1: x0 + 10.0,
            y1: 20.0,
            area_px: 200,
            similarity: None,
            iterations: None,
            camera_moving: false,
        }
    }

    fn gt(frame: i64, x0: f64) -> GtBoxRow {
        GtBoxRow {
            frame,
            id: person_key(1, 1.76),
            x0,
            y0: 0.0,
            x1: x0 + 10.0,
            y1: 20.0,
            visibility: 1.0,
        }
    }

    fn session(
        tracks: &[TrackRow],
        boxes: &[GtBoxRow],
        has_gt: bool,
        row: SessionRow,
    ) -> SessionTables {
        let mut t = SessionTables::new();
        t.insert(TRACKS_TABLE.into(), TrackRow::frame(tracks).expect("frame"));
        t.insert(GT_TABLE.into(), GtBoxRow::frame(boxes).expect("frame"));
        t.insert(
            HAS_GT_TABLE.into(),
            df! { "value" => [has_gt] }.expect("df"),
        );
        t.insert(
            super::super::shared::SESSION_TABLE.into(),
            SessionRow::frame(&[row]).expect("frame"),
        );
        t
    }

    #[test]
    fn person_keys_keep_people_that_share_an_id_apart() {
        assert_eq!(person_key(1, 1.76), 101_760);
        assert_ne!(person_key(1, 1.76), person_key(1, 1.60));
    }

    #[test]
    fn a_dataset_row_sums_sessions_and_scores_tracks_against_boxes() {
        // frames 0–3: a person; the track follows it in frames 0–2 (colour in frame 2), then
        // drifts off (IoU 0) in frame 3: 3 matches, 1 miss, 1 false positive
        let colour = Mode::Colour(HandOver::StandingStill);
        let a = session(
            &[
                track(0, 7, 0.0, Mode::Blob),
                track(1, 7, 1.0, Mode::Blob),
                track(2, 7, 2.0, colour),
                track(3, 7, 40.0, colour),
            ],
            &[gt(0, 0.0), gt(1, 1.0), gt(2, 2.0), gt(3, 3.0)],
            true,
            SessionRow {
                frames: 4,
                moving_frames: 1,
                tracks_started: 1,
                handovers_still: 1,
                ..Default::default()
            },
        );
        // a session without ground truth counts, but is not scored
        let b = session(
            &[track(0, 1, 0.0, Mode::Blob)],
            &[],
            false,
            SessionRow {
                frames: 2,
                tracks_started: 1,
                ..Default::default()
            },
        );
        let (row, m) = dataset_row("d", &[&a, &b], &LocalEvalParams::default()).expect("row");
        assert!(m.is_some());
        assert_eq!(
            (row.sessions, row.frames, row.camera_moving_frames),
            (2, 6, 1)
        );
        assert_eq!((row.tracks, row.observations), (2, 5));
        assert_eq!(
            (row.colour_camera_moving, row.colour_standing_still),
            (0, 2)
        );
        assert_eq!(row.handovers_still, 1);
        assert_eq!(row.misses, Some(1));
        assert_eq!(row.false_positives, Some(1));
        assert_eq!(row.id_switches, Some(0));
        assert_eq!(row.mota, Some(0.5));
        assert_eq!(row.recall, Some(0.75));
        let (none, m) = dataset_row("d", &[&b], &LocalEvalParams::default()).expect("row");
        assert!(m.is_none() && none.mota.is_none());
    }
}
