//! What every sub-experiment shares: the frame it is handed, the per-session `session` table
//! and the grouping of sessions by dataset at aggregation.

use image::RgbImage;

use crate::groundtruth::PeopleFrame;
use crate::report::rows::Rows;
use crate::run::{Aggregate, SessionTables};
use crate::table_row;
use crate::vision::ImageView;

/// One camera frame as the sub-experiments see it.
#[derive(Clone, Copy)]
pub(super) struct Frame<'a> {
    /// Index in the session, from 0.
    pub index: i64,
    /// Seconds since the session's first frame (header stamps).
    pub t_s: f64,
    pub rgb: &'a RgbImage,
    pub view: ImageView<'a>,
    /// The exact person mask (255 = person), when the session has one for this frame.
    pub mask: Option<&'a [u8]>,
    /// The per-person id mask (each pixel the id of the person seen there, 0 none), when a
    /// re-identified session without an exact person mask has one for this frame.
    pub person_ids: Option<&'a [u8]>,
    /// The ground truth joined to this frame (nearest stamp).
    pub truth: Option<&'a PeopleFrame>,
    /// Odometry says the camera moves.
    pub moving: bool,
}

table_row! {
    /// The cached `session` table (one row): what was read, and each stage's counters.
    #[derive(Debug, Clone, Default, PartialEq)]
    pub(super) struct SessionRow {
        pub dataset: String,
        pub session: String,
        pub frames: i64,
        pub width: i64,
        pub height: i64,
        pub has_mask: bool,
        pub bad_images: i64,
        pub bad_masks: i64,
        pub frames_without_mask: i64,
        pub bad_ground_truth: i64,
        pub bad_odometry: i64,
        pub first_error: String,
        pub moving_frames: i64,
        pub camera_rides_robot: bool,
        pub gmm_restarts: i64,
        pub tracks_started: i64,
        pub handovers_camera: i64,
        pub handovers_still: i64,
        pub reacquired: i64,
        pub colour_frame0: Option<i64>,
    }
}

/// Name of the cached table of [`SessionRow`].
pub(super) const SESSION_TABLE: &str = "session";

/// A session's [`SessionRow`] (defaults where the table is missing or unreadable).
pub(super) fn session_row(tables: &SessionTables) -> SessionRow {
    tables
        .get(SESSION_TABLE)
        .and_then(|d| SessionRow::read(d).ok())
        .and_then(|v| v.into_iter().next())
        .unwrap_or_default()
}

/// Datasets in first-seen order with their sessions.
pub(super) fn by_dataset<'a>(ctx: &'a Aggregate) -> Vec<(String, Vec<&'a SessionTables>)> {
    let mut out: Vec<(String, Vec<&SessionTables>)> = Vec::new();
    for (info, tables) in ctx.sessions {
        match out.iter_mut().find(|(d, _)| *d == info.dataset) {
            Some((_, v)) => v.push(tables),
            None => out.push((info.dataset.clone(), vec![tables])),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_session_row_round_trips_and_a_missing_table_reads_as_defaults() {
        let row = SessionRow {
            dataset: "d".into(),
            frames: 12,
            colour_frame0: Some(3),
            camera_rides_robot: true,
            ..Default::default()
        };
        let mut t = SessionTables::new();
        assert_eq!(session_row(&t), SessionRow::default());
        t.insert(
            SESSION_TABLE.into(),
            SessionRow::frame(std::slice::from_ref(&row)).expect("frame"),
        );
        assert_eq!(session_row(&t), row);
    }
}
