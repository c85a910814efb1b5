//! The BIRON dataset's extra channels (seed 003, issue 33), JSON like the rest of the ground
//! truth: `/ground_truth/biron` every step (who speaks, to whom, who looks at the robot, each
//! visible face, the true category and the true focus of attention), `/ground_truth/utterances`
//! once at the start (every utterance with its speaker, interval, addressee and dialog kind),
//! and `/attention/state`, the system's own output at every step (a real robot logs this too:
//! it is what drove the pan-tilt unit). Positions in `map` (m), angles in degrees.

use serde::{Deserialize, Serialize};

pub const BIRON_TOPIC: &str = "/ground_truth/biron";
pub const BIRON_SCHEMA: &str = "peopletrack.BironGroundTruth";
pub const UTTERANCES_TOPIC: &str = "/ground_truth/utterances";
pub const UTTERANCES_SCHEMA: &str = "peopletrack.Utterances";
pub const ATTENTION_TOPIC: &str = "/attention/state";
pub const ATTENTION_SCHEMA: &str = "peopletrack.AttentionState";

/// A face as the camera saw it at a step (from the renderer's object ids).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaceTruth {
    /// Projected head centre (px).
    pub center_px: [f64; 2],
    /// Projected head width (px): 0.17 m at the head's distance.
    pub width_px: f64,
    /// Angle between where the face looks and the camera (0: frontal), degrees.
    pub yaw_deg: f64,
    /// Share of the head's box showing this person's pixels (0 when occluded or cut).
    pub visible: f64,
}

/// One person at a step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BironPerson {
    pub id: u32,
    pub x: f64,
    pub y: f64,
    pub mouth: [f64; 3],
    pub head_yaw_deg: f64,
    pub speaking: bool,
    /// `robot`, a person id as text, or empty when silent.
    pub addressee: String,
    pub looking_at_robot: bool,
    /// In the region the robot senses (the laser's field of view and range).
    pub in_region: bool,
    /// The seed's category (1, 2, 3) from the true cues.
    pub category: u8,
    pub face: Option<FaceTruth>,
}

/// `/ground_truth/biron`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BironFrame {
    pub stamp_ns: u64,
    pub people: Vec<BironPerson>,
    /// The attention state machine run on the true cues and dialog events.
    pub mode: String,
    pub focus: Option<u32>,
    /// Dialog events that took effect at this step: `greeting:<id>`, `goodbye:<id>`.
    pub events: Vec<String>,
}

/// One utterance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UtteranceTruth {
    pub index: usize,
    pub speaker: u32,
    pub start_ns: u64,
    pub end_ns: u64,
    /// `robot` or a person id as text.
    pub addressee: String,
    /// `greeting`, `talk` or `goodbye`.
    pub kind: String,
    /// The mouth when the utterance starts (m).
    pub mouth: [f64; 3],
}

/// `/ground_truth/utterances`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UtterancesFrame {
    pub stamp_ns: u64,
    pub utterances: Vec<UtteranceTruth>,
}

/// One person anchor in `/attention/state`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnchorState {
    pub id: u64,
    pub x: f64,
    pub y: f64,
    pub height: f64,
    /// Component states: `grounded`, `associated`, `lost`.
    pub legs: String,
    pub face: String,
    pub torso: String,
    pub voice: String,
    pub category: u8,
}

/// `/attention/state`: the system's output at a step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttentionState {
    pub stamp_ns: u64,
    pub mode: String,
    pub focus: Option<u64>,
    /// Pan-tilt command for the next frame (deg).
    pub pan_deg: f64,
    pub tilt_deg: f64,
    pub anchors: Vec<AnchorState>,
    /// The sound percept's anchor, when one was active and landed.
    pub sound_anchor: Option<u64>,
}

/// A permissive JSON Schema (an object with a stamp) for these channels.
pub fn json_schema(title: &str) -> String {
    format!(
        r#"{{"$schema": "https://json-schema.org/draft/2020-12/schema", "title": "{title}", "type": "object", "required": ["stamp_ns"], "properties": {{"stamp_ns": {{"type": "integer"}}}}}}"#
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schemas_are_json_and_frames_round_trip() {
        serde_json::from_str::<serde_json::Value>(&json_schema(BIRON_SCHEMA)).expect("schema");
        let f = AttentionState {
            stamp_ns: 5,
            mode: "listen".into(),
            focus: Some(2),
            pan_deg: 10.0,
            tilt_deg: -3.0,
            anchors: vec![AnchorState {
                id: 2,
                x: 1.0,
                y: 2.0,
                height: 1.7,
                legs: "grounded".into(),
                face: "lost".into(),
                torso: "associated".into(),
                voice: "grounded".into(),
                category: 2,
            }],
            sound_anchor: None,
        };
        let s = serde_json::to_string(&f).expect("json");
        assert_eq!(serde_json::from_str::<AttentionState>(&s).expect("back"), f);
    }
}
