//! `s003_biron_anchoring` — seed 003's BIRON chapter (Wrede et al. 2004, §IV; multi-modal
//! anchoring after Fritsch et al. 2003, the attention system of Lang et al. 2003): persons
//! anchored from laser legs, frontal faces, torso colour and two-microphone sound
//! localisation, and the three-category attention state machine, on the `biron_home` logs.
//!
//! Per session ([`session`]): one pass over scans, camera frames and the nominal audio,
//! every system variant of [`params::VARIANTS`] stepped on the same percepts
//! ([`crate::anchoring`]); the scores of [`score`] (faces, CLEAR MOT of the person anchors,
//! focus of attention per 100 ms step, speaker identification per sound block, the anchor
//! timeline, the replay against the logged `/attention/state`); the direction of arrival of
//! every acoustic condition and the correlogram ([`doa`]); all cached as [`tables`].
//! Aggregation ([`aggregate`]): the tables beside the targets, paired t-tests of each
//! ablation against the full system across sessions (Holm-corrected), and the figures
//! ([`figures`]).

mod aggregate;
pub mod doa;
mod figures;
pub mod params;
pub mod score;
mod session;
pub mod tables;

use std::collections::BTreeMap;

use crate::frames;
use crate::progress::Progress;
use crate::run::config::Invalid;
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

pub use params::Params;

pub struct BironAnchoring;

const TOPIC_KEYS: [(&str, &str); 4] = [
    ("audio", "/audio"),
    ("scan", "/scan"),
    ("image", "/camera/image_raw/compressed"),
    ("camera_info", "/camera/camera_info"),
];

fn topics(t: &BTreeMap<String, String>) -> session::Topics {
    let get = |k: &str, d: &str| frames::topic(t, k, d);
    session::Topics {
        audio: get(TOPIC_KEYS[0].0, TOPIC_KEYS[0].1),
        scan: get(TOPIC_KEYS[1].0, TOPIC_KEYS[1].1),
        image: get(TOPIC_KEYS[2].0, TOPIC_KEYS[2].1),
        info: get(TOPIC_KEYS[3].0, TOPIC_KEYS[3].1),
    }
}

impl Experiment for BironAnchoring {
    const KIND: &'static str = "s003_biron_anchoring";
    const VERSION: u32 = 1;
    const SESSION_TABLES: &'static [crate::run::schemas::TableDoc] = tables::SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        params::validate(p)
    }

    fn topic_keys(_: &Params) -> Vec<String> {
        TOPIC_KEYS.iter().map(|(k, _)| (*k).to_string()).collect()
    }

    fn plan(_: &Params, t: &BTreeMap<String, String>) -> Vec<Stage> {
        let tp = topics(t);
        vec![
            Stage {
                name: "laser legs and people tracker (seed 002's leg model)".into(),
                requires: vec![tp.scan.clone(), "/tf_static".into()],
                optional: vec![],
            },
            Stage {
                name: "frontal faces and torso colour (pan-tilt camera)".into(),
                requires: vec![tp.image.clone(), tp.info.clone(), "/tf".into()],
                optional: vec![],
            },
            Stage {
                name: "GCC-PHAT sound localisation, every acoustic condition".into(),
                requires: vec![tp.audio.clone(), frames::audio::info_topic(&tp.audio)],
                optional: vec![],
            },
            Stage {
                name: "anchoring + attention, variants; ground truth".into(),
                requires: vec![
                    crate::groundtruth::biron::BIRON_TOPIC.into(),
                    crate::groundtruth::biron::UTTERANCES_TOPIC.into(),
                ],
                optional: vec![crate::groundtruth::biron::ATTENTION_TOPIC.into()],
            },
        ]
    }

    fn process(
        s: &Session,
        p: &Params,
        t: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        session::process(s, p, &topics(t), bar)
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        let data = aggregate::load(ctx)?;
        let mut out = aggregate::products(&data, p)?;
        out.figures
            .extend(figures::all(&data, &aggregate::doa_cells(&data)));
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::config;

    #[test]
    fn the_shipped_pipeline_file_states_the_code_defaults_and_bad_values_are_named() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("pipelines/s003_biron_anchoring.toml");
        let text = std::fs::read_to_string(&path).expect("pipeline file");
        let file = config::parse::<Params>(&path, &text).expect("parses");
        assert!(BironAnchoring::validate(&file.params).is_empty());
        assert_eq!(file.params, Params::default());
        let p = Params {
            rate_hz: 0.0,
            doa_single_share: 0.2,
            level: 1.0,
            ..Params::default()
        };
        let named: Vec<String> = BironAnchoring::validate(&p)
            .into_iter()
            .map(|(k, _)| k)
            .collect();
        assert_eq!(named, ["rate_hz", "doa_single_share", "level"]);
    }
}
