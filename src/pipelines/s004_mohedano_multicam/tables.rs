//! The per-session tables (cached as Parquet): one row struct each. `session` writes them,
//! the aggregation (`scored`, `evaluate`, `figures`, `markers`) reads them back; nothing
//! else passes between the two.

use crate::run::schemas::{TableDoc, table};
use crate::table_row;

/// Names of the cached per-session tables.
pub(crate) const CALIBRATION: &str = "calibration";
pub(crate) const TRACKS: &str = "tracks";
pub(crate) const GT: &str = "gt";
pub(crate) const HEAD_CENTROID: &str = "head_centroid";
pub(crate) const CAMERAS: &str = "cameras";
pub(crate) const DETECTIONS_2D: &str = "detections_2d";
/// Every miss and false detection of the template chain with its cause (`session::errors`).
pub(crate) const ERRORS_2D: &str = "errors_2d";
pub(crate) const VARIANTS: &str = "variants";
/// MEASURED: seconds of the 3-D stage per frame (main run); left out by tools/compare_out.py.
pub(crate) const TIMING_3D: &str = "timing_3d";
pub(crate) const SESSION: &str = "session";
/// The camera images at the frame the camera-view figure shows (`report::columns::image_table`).
pub(crate) const VIEW_IMAGE: &str = "view_image";
/// That frame and the cylinders projected into it.
pub(crate) const VIEW_SHAPES: &str = "view_shapes";
pub(crate) const VIEW_FRAME: &str = "view_frame";
/// The detector-noise runs' tracks (`TrackRow`: `detector` = the noise level, `selection` =
/// the association) and each level's box counts; absent without `detector_noise`.
pub(crate) const NOISE_TRACKS: &str = "noise_tracks";
pub(crate) const NOISE_BOXES: &str = "noise_boxes";

/// Every per-session table and what a row of it is (`docs/schemas.md`).
pub(crate) const SESSION_TABLES: &[TableDoc] = &[
    table(
        CALIBRATION,
        "One camera's position and heading in the world frame.",
    ),
    table(
        TRACKS,
        "One 3-D track in one frame of one run (detector, selection rule, `N_app`).",
    ),
    table(GT, "One ground-truth person at one frame."),
    table(
        HEAD_CENTROID,
        "Ground error of triangulating one person's head points and blob centroids at one frame.",
    ),
    table(
        CAMERAS,
        "One camera's image stages at one frame (templates detector).",
    ),
    table(
        DETECTIONS_2D,
        "Template detections of one camera at one frame against the visible ground-truth boxes; \
         head offsets and height ratios are sums over the matched pairs.",
    ),
    table(
        ERRORS_2D,
        "One miss or false detection of the template chain at one frame and camera, with its \
         cause; scores are NaN where they do not apply.",
    ),
    table(VARIANTS, "The search statistics of one 3-D run."),
    table(
        TIMING_3D,
        "One frame of the main run's 3-D stage, timed (fastest of 3 steps; measured, varies).",
    ),
    table(SESSION, "The session as a whole (one row)."),
    table(
        VIEW_IMAGE,
        "The camera images at the frame the camera-view figure shows, as PNG bytes.",
    ),
    table(
        VIEW_SHAPES,
        "One vertex of a shape drawn over the camera-view canvas: polyline vertices in order, or \
         the two corners of a labelled box.",
    ),
    table(
        VIEW_FRAME,
        "The frame of the camera-view figure (one row), or why there is no view.",
    ),
    table(
        NOISE_TRACKS,
        "The detector-noise runs' tracks (the columns of `tracks`: `detector` = the noise level, \
         `selection` = the association); only with `detector_noise`.",
    ),
    table(
        NOISE_BOXES,
        "The boxes of one noise level in one session, before and after the detector model; only \
         with `detector_noise`.",
    ),
];

table_row! {
    /// The boxes of one noise level in one session: before and after the detector model.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct NoiseBoxRow {
        pub noise: String,
        pub clean: i64,
        pub noisy: i64,
    }
}

table_row! {
    /// One 3-D track in one frame of one run (detector, selection rule, `N_app`).
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct TrackRow {
        pub detector: String,
        pub selection: String,
        pub n_app: i64,
        pub frame: i64,
        pub stamp_ns: i64,
        pub t_s: f64,
        pub id: i64,
        pub x_m: f64,
        pub y_m: f64,
        pub vx_mps: f64,
        pub vy_mps: f64,
        pub height_m: f64,
        pub radius_m: f64,
        pub cameras: i64,
        /// Supporting cameras as `camera:2-D id`, space separated.
        pub support: String,
        /// E_m of the supporting combination (none while the track coasts).
        pub e_m_px: Option<f64>,
        pub meas_x_m: Option<f64>,
        pub meas_y_m: Option<f64>,
        pub meas_height_m: Option<f64>,
        pub meas_radius_m: Option<f64>,
    }
}

table_row! {
    /// One ground-truth person at one frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct GtRow {
        pub frame: i64,
        pub stamp_ns: i64,
        pub t_s: f64,
        pub id: i64,
        pub x_m: f64,
        pub y_m: f64,
        pub height_m: f64,
        pub radius_m: f64,
        pub cameras_visible: i64,
        pub in_room: bool,
    }
}

table_row! {
    /// Ground error of triangulating one person's head points and blob centroids at one frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct HeadCentroidRow {
        pub detector: String,
        pub frame: i64,
        pub id: i64,
        pub cameras: i64,
        pub occluded: bool,
        pub clear: bool,
        pub min_visibility: f64,
        pub head_error_m: f64,
        pub centroid_error_m: f64,
    }
}

table_row! {
    /// Template detections of one camera at one frame against the visible ground-truth boxes;
    /// head offsets and height ratios are sums over the matched pairs.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct Det2dRow {
        pub frame: i64,
        pub camera: String,
        pub truth: i64,
        pub detections: i64,
        pub matched: i64,
        pub head_dx_abs_px: f64,
        pub head_dy_px: f64,
        pub height_ratio: f64,
    }
}

table_row! {
    /// One miss or false detection of the template chain at one frame and camera, with its
    /// cause (`session::errors`); scores are NaN where they do not apply.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct Error2dRow {
        pub frame: i64,
        pub camera: String,
        /// "miss" or "false".
        pub kind: String,
        pub cause: String,
        /// The missed person's id (-1 for a false detection).
        pub person: i64,
        pub visibility: f64,
        pub speed_mps: f64,
        /// Misses: the person's own silhouette at the true head, the best of the whole
        /// template set and the best the detector tried near the head.
        pub exact_score: f64,
        pub any_score: f64,
        pub set_score: f64,
        /// False detections: the detection's score.
        pub det_score: f64,
    }
}

table_row! {
    /// One camera's image stages at one frame (templates detector).
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct CameraRow {
        pub frame: i64,
        pub camera: String,
        pub threshold: f64,
        pub foreground_frac: f64,
        pub detections: i64,
        pub objects_2d: i64,
    }
}

table_row! {
    /// The search statistics of one 3-D run.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct VariantRow {
        pub detector: String,
        pub selection: String,
        pub n_app: i64,
        pub combinations: i64,
        pub pruned_frames: i64,
        pub promoted: i64,
        pub discarded: i64,
    }
}

table_row! {
    /// One frame of the main run's 3-D stage, timed (fastest of 3 steps on tracker clones).
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct Timing3dRow {
        pub detector: String,
        pub association: String,
        pub cameras: i64,
        pub frame: i64,
        pub objects_2d: i64,
        pub seconds: f64,
    }
}

table_row! {
    /// The session as a whole (one row).
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct SessionRow {
        pub frames: i64,
        pub cameras: i64,
        pub dt_s: f64,
        pub duration_s: f64,
        pub first_stamp_ns: i64,
        pub decode_failures: i64,
        pub missing_camera_frames: i64,
        pub gt_frames: i64,
        pub gt_bad_frames: i64,
        pub first_error: String,
    }
}

table_row! {
    /// One camera's position and heading in the world frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct CalibRow {
        pub camera: String,
        pub x_m: f64,
        pub y_m: f64,
        pub z_m: f64,
        pub heading_rad: f64,
    }
}

table_row! {
    /// The frame of the camera-view figure (one row), or why there is no view.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct ViewFrameRow {
        pub frame: i64,
        pub t_s: f64,
        /// Empty, or why the view could not be made.
        pub error: String,
    }
}

table_row! {
    /// One vertex of a shape drawn over the camera-view canvas: polyline vertices in order,
    /// or the two corners of a labelled box.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct ViewShapeRow {
        pub shape: i64,
        /// "polyline" or "box".
        pub kind: String,
        pub color: i64,
        pub label: String,
        pub x: f64,
        pub y: f64,
    }
}
