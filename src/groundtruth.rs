//! The ground truth synthetic sessions carry as JSON channels (absent in real logs):
//! `/ground_truth/people` every frame (schema `peopletrack.PeopleGroundTruth`) and
//! `/ground_truth/calibration_targets` during calibration segments
//! (`peopletrack.CalibrationTargets`). Positions are metres in the `map` frame (z up, ground
//! z = 0); pixels are in each camera's raw image.

use serde::{Deserialize, Serialize};

pub mod biron;

pub const PEOPLE_TOPIC: &str = "/ground_truth/people";
pub const PEOPLE_SCHEMA: &str = "peopletrack.PeopleGroundTruth";
pub const TARGETS_TOPIC: &str = "/ground_truth/calibration_targets";
pub const TARGETS_SCHEMA: &str = "peopletrack.CalibrationTargets";
pub const FOLLOWER_TOPIC: &str = "/follower/state";
pub const FOLLOWER_SCHEMA: &str = "peopletrack.FollowerState";

/// `/follower/state`: a following robot's tracker output and command at one scan. Unlike the
/// ground truth, a real following robot logs this too (seed 001's figures join the robot's
/// path to each estimate and plot the covariance norm with the `rst` events). Frame `odom`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FollowerState {
    /// The scan's header stamp (ns).
    pub stamp_ns: u64,
    /// Frame of the positions (`odom`).
    pub frame_id: String,
    /// Target position (m); `None` (null) while the target is lost.
    pub position: Option<[f64; 2]>,
    /// Target velocity (m/s).
    pub velocity: Option<[f64; 2]>,
    /// Position covariance (m²).
    pub covariance: Option<[[f64; 2]; 2]>,
    /// The track was dropped at this scan to be re-initialised (`rst`).
    pub reset: bool,
    /// The following controller (`pursuit`, `direct`).
    pub controller: String,
    /// Commanded forward speed (m/s) and yaw rate (rad/s).
    pub command_v: f64,
    pub command_w: f64,
    /// Desired following distance `d_follow + v²/(2·a_min)` (m).
    pub desired_distance: f64,
    /// The robot's odometry pose `[x, y, yaw]` at the scan (m, rad).
    pub robot: [f64; 3],
    /// While the target is lost after `rst`: the last prediction the robot turns towards
    /// (absent otherwise, and in logs written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub look_at: Option<[f64; 2]>,
    /// The platform's obstacle check changed the controller's command (absent: it did not,
    /// or the log predates the check).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub avoided: bool,
    /// The robot's footprint touched an obstacle since the previous scan (a bumper's report;
    /// absent: it did not, or the log predates the footprint).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub contact: bool,
}

/// What one camera sees of one person.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraView {
    /// Camera name as in its topics (`cam_0`, `omni_camera`).
    pub camera: String,
    /// Bounding box `[x0, y0, x1, y1]` of the visible pixels, if any are visible; right and
    /// bottom exclusive (the last visible column is `x1 - 1`).
    pub bbox: Option<[f64; 4]>,
    /// Projection of the top of the head, if it is inside the image.
    pub head_px: Option<[f64; 2]>,
    /// Fraction of the person's pixels not hidden by occluders or other people (0–1).
    pub visibility: f64,
}

/// One person at one instant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PersonTruth {
    pub id: u32,
    /// Body centre on the ground (m).
    pub x: f64,
    pub y: f64,
    /// Velocity (m/s).
    pub vx: f64,
    pub vy: f64,
    /// Top of the head above the ground (m).
    pub height: f64,
    /// Centre of the head above the ground (m).
    pub head_z: f64,
    /// Body (shoulder) radius (m).
    pub radius: f64,
    /// Leg centres at laser height `[[x, y], [x, y]]` (m).
    pub legs: [[f64; 2]; 2],
    pub leg_radius: f64,
    pub cameras: Vec<CameraView>,
}

/// `/ground_truth/people`: everyone in the scene at one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeopleFrame {
    pub stamp_ns: u64,
    pub people: Vec<PersonTruth>,
}

/// A known position used by calibration (e.g. the hat of a person standing on a marker).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    pub id: u32,
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// `/ground_truth/calibration_targets`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetsFrame {
    pub stamp_ns: u64,
    pub targets: Vec<Target>,
}

/// JSON Schema of `/ground_truth/people` (stored in the log's schema record).
pub const PEOPLE_JSON_SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "peopletrack.PeopleGroundTruth",
  "type": "object",
  "required": ["stamp_ns", "people"],
  "properties": {
    "stamp_ns": {"type": "integer", "description": "time of the state (ns)"},
    "people": {"type": "array", "items": {
      "type": "object",
      "required": ["id", "x", "y", "vx", "vy", "height", "head_z", "radius", "legs", "leg_radius", "cameras"],
      "properties": {
        "id": {"type": "integer"},
        "x": {"type": "number", "description": "body centre, map frame (m)"},
        "y": {"type": "number"},
        "vx": {"type": "number", "description": "velocity (m/s)"},
        "vy": {"type": "number"},
        "height": {"type": "number", "description": "top of head above ground (m)"},
        "head_z": {"type": "number", "description": "head centre above ground (m)"},
        "radius": {"type": "number", "description": "body radius (m)"},
        "legs": {"type": "array", "items": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "minItems": 2, "maxItems": 2},
        "leg_radius": {"type": "number"},
        "cameras": {"type": "array", "items": {
          "type": "object",
          "required": ["camera", "visibility"],
          "properties": {
            "camera": {"type": "string"},
            "bbox": {"type": ["array", "null"], "items": {"type": "number"}, "minItems": 4, "maxItems": 4},
            "head_px": {"type": ["array", "null"], "items": {"type": "number"}, "minItems": 2, "maxItems": 2},
            "visibility": {"type": "number", "minimum": 0, "maximum": 1}
          }
        }}
      }
    }}
  }
}"#;

/// JSON Schema of `/ground_truth/calibration_targets`.
pub const TARGETS_JSON_SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "peopletrack.CalibrationTargets",
  "type": "object",
  "required": ["stamp_ns", "targets"],
  "properties": {
    "stamp_ns": {"type": "integer"},
    "targets": {"type": "array", "items": {"type": "object", "required": ["id", "x", "y", "z"],
      "properties": {"id": {"type": "integer"}, "x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}}}
  }
}"#;

/// JSON Schema of `/follower/state`.
pub const FOLLOWER_JSON_SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "peopletrack.FollowerState",
  "type": "object",
  "required": ["stamp_ns", "frame_id", "position", "velocity", "covariance", "reset", "controller", "command_v", "command_w", "desired_distance", "robot"],
  "properties": {
    "stamp_ns": {"type": "integer", "description": "scan stamp (ns)"},
    "frame_id": {"type": "string", "description": "frame of the positions (odom)"},
    "position": {"type": ["array", "null"], "items": {"type": "number"}, "minItems": 2, "maxItems": 2, "description": "target position (m), null when lost"},
    "velocity": {"type": ["array", "null"], "items": {"type": "number"}, "minItems": 2, "maxItems": 2, "description": "target velocity (m/s)"},
    "covariance": {"type": ["array", "null"], "items": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}, "minItems": 2, "maxItems": 2, "description": "position covariance (m^2)"},
    "reset": {"type": "boolean", "description": "rst: the track was dropped at this scan"},
    "controller": {"type": "string", "enum": ["pursuit", "direct"]},
    "command_v": {"type": "number", "description": "commanded speed (m/s)"},
    "command_w": {"type": "number", "description": "commanded yaw rate (rad/s)"},
    "desired_distance": {"type": "number", "description": "d_follow + v^2/(2 a_min) (m)"},
    "robot": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3, "description": "odometry pose x, y, yaw (m, rad)"}
  }
}"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schemas_are_valid_json_and_frames_round_trip() {
        serde_json::from_str::<serde_json::Value>(PEOPLE_JSON_SCHEMA).expect("people schema");
        serde_json::from_str::<serde_json::Value>(TARGETS_JSON_SCHEMA).expect("targets schema");
        serde_json::from_str::<serde_json::Value>(FOLLOWER_JSON_SCHEMA).expect("follower schema");
        let f = PeopleFrame {
            stamp_ns: 5,
            people: vec![PersonTruth {
                id: 1,
                x: 1.0,
                y: 2.0,
                vx: 0.5,
                vy: 0.0,
                height: 1.8,
                head_z: 1.69,
                radius: 0.22,
                legs: [[1.0, 2.1], [1.0, 1.9]],
                leg_radius: 0.06,
                cameras: vec![CameraView {
                    camera: "cam_0".into(),
                    bbox: Some([1.0, 2.0, 3.0, 4.0]),
                    head_px: None,
                    visibility: 0.75,
                }],
            }],
        };
        let s = serde_json::to_string(&f).expect("serialise");
        assert_eq!(serde_json::from_str::<PeopleFrame>(&s).expect("parse"), f);
        assert!(
            serde_json::from_str::<PeopleFrame>(r#"{"stamp_ns":1,"people":[],"extra":1}"#).is_err()
        );
    }
}
