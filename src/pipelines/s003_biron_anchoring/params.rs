//! Parameters of `s003_biron_anchoring` (the `[params]` table) and their checks. The
//! system's own settings are [`crate::anchoring::system::SystemParams`]'s defaults (chosen a
//! priori, see there); these are the evaluation's.

use serde::{Deserialize, Serialize};

use crate::anchoring::Modalities;
use crate::run::config::Invalid;

/// The system variants the pipeline runs: the whole system and one modality off each.
pub const VARIANTS: [(&str, Modalities); 5] = [
    ("full", Modalities::ALL),
    (
        "no_sound",
        Modalities {
            sound: false,
            ..Modalities::ALL
        },
    ),
    (
        "no_faces",
        Modalities {
            faces: false,
            ..Modalities::ALL
        },
    ),
    (
        "no_legs",
        Modalities {
            legs: false,
            ..Modalities::ALL
        },
    ),
    (
        "no_torso",
        Modalities {
            torso: false,
            ..Modalities::ALL
        },
    ),
];

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Step rate of the system: the camera's frame rate (Hz).
    pub rate_hz: f64,
    /// Direction-of-arrival blocks (s): the 0.5 s.
    pub doa_block_s: f64,
    /// A DOA block counts when one utterance covers at least this share of it and no other
    /// utterance touches it.
    pub doa_single_share: f64,
    /// CLEAR MOT match distance for person anchors (m): the 0.5 m.
    pub mot_max_m: f64,
    /// A detected face matches a true one when its centre is within this share of the true
    /// head width and its width within a factor 2.
    pub face_match_share: f64,
    /// A true face counts when at least this share of its head box shows the person (an
    /// unoccluded ellipse fills ~0.78 of its box).
    pub face_visible_min: f64,
    /// A face this close to frontal (deg) is frontal.
    pub frontal_max_deg: f64,
    /// Seconds of the nominal stream drawn in the correlogram.
    pub correlogram_s: f64,
    pub level: f64,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            rate_hz: 10.0,
            doa_block_s: 0.5,
            doa_single_share: 0.8,
            mot_max_m: 0.5,
            face_match_share: 0.5,
            face_visible_min: 0.6,
            frontal_max_deg: 15.0,
            correlogram_s: 20.0,
            level: 0.95,
        }
    }
}

pub fn validate(p: &Params) -> Vec<Invalid> {
    let mut out = Vec::new();
    let mut check = |ok: bool, key: &str, reason: &str| {
        if !ok {
            out.push((key.to_string(), reason.to_string()));
        }
    };
    check(
        (1.0..=30.0).contains(&p.rate_hz),
        "rate_hz",
        "must be in [1, 30] Hz",
    );
    check(
        (0.1..=5.0).contains(&p.doa_block_s),
        "doa_block_s",
        "must be in [0.1, 5] s",
    );
    check(
        (0.5..=1.0).contains(&p.doa_single_share),
        "doa_single_share",
        "must be in [0.5, 1]",
    );
    check(p.mot_max_m > 0.0, "mot_max_m", "must be positive");
    check(
        p.face_match_share > 0.0,
        "face_match_share",
        "must be positive",
    );
    check(
        (0.0..=1.0).contains(&p.face_visible_min),
        "face_visible_min",
        "must be in [0, 1]",
    );
    check(
        (0.0..=90.0).contains(&p.frontal_max_deg),
        "frontal_max_deg",
        "must be in [0, 90]",
    );
    check(
        (1.0..=120.0).contains(&p.correlogram_s),
        "correlogram_s",
        "must be in [1, 120] s",
    );
    check(
        p.level > 0.5 && p.level < 1.0,
        "level",
        "must be in (0.5, 1)",
    );
    out
}
