//! `s001_kobilarov_following` — seed 001 (Kobilarov, Sukhatme, Hyams & Batavia, "People
//! tracking and following with mobile robot using an omnidirectional camera and a laser"):
//! a balancing robot follows a jogger in a park, closed loop, driven by its own laser + omni
//! PDAF tracker (`synth::follow` drives it in the synthesizer, with `laser::follow`).
//!
//! Per session ([`session`], cached as the rows of [`tables`]): every method of
//! [`params::METHODS`] replayed on the log's scans and omni frames ([`replay`]: the paper's
//! coordinated-turn PDAF with colour, CV, IMM (ours), without colour, nearest neighbour, and
//! the laser issue's tracker), the ground truth and the laser's view of the person
//! ([`scene`]), method 1 on the omni frames ([`method1`]) and the closed loop's own logged
//! tracker output ([`closed_loop`]); a real laser log goes through [`real`] instead.
//! Aggregation ([`aggregate`]): Table I, "followed" and the rst events ([`table1`]), the
//! methods, their re-acquisitions and the Holm-corrected t-tests ([`compare`]), the colour
//! descriptor's separation of target and clutter and the clutter density ([`colour`]), how
//! each method first loses the person ([`losses`]), method 1's loss rate, the real log, the
//! figures ([`figures`]).

mod aggregate;
mod closed_loop;
mod colour;
mod compare;
mod figures;
mod losses;
mod method1;
mod params;
mod pose;
mod real;
mod replay;
mod scene;
mod session;
mod table1;
mod tables;

use std::collections::BTreeMap;

use crate::progress::Progress;
use crate::run::config::Invalid;
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

pub use params::Params;

pub struct KobilarovFollowing;

impl Experiment for KobilarovFollowing {
    const KIND: &'static str = "s001_kobilarov_following";
    const VERSION: u32 = 8; // 8: the platform (avoided, contact; Table I contacts);
    // 7: // 5: ct_colour_others (the other people tracked) and loop_method;
    // 6: the other tracks weigh blobs by their own colour; 7: `obstacle` (truth, rst causes,
    // losses)
    const SESSION_TABLES: &'static [crate::run::schemas::TableDoc] = tables::SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        params::validate(p)
    }

    fn plan(p: &Params, _: &BTreeMap<String, String>) -> Vec<Stage> {
        let mut laser = vec![p.scan_topic.clone(), "/tf".into(), "/tf_static".into()];
        laser.extend(
            p.real
                .iter()
                .flat_map(|r| [r.scan_topic.clone(), r.gt_topic.clone()]),
        );
        vec![
            Stage {
                name: "laser blobs + replayed trackers (seed 001 §V)".into(),
                requires: vec![],
                optional: laser,
            },
            Stage {
                name: "omni colour ROIs (§V) and method 1 (§IV)".into(),
                requires: vec![],
                optional: vec![
                    format!("/{}/camera_info", p.camera),
                    format!("/{}/image_raw", p.camera),
                    format!("/{}/image_raw/compressed", p.camera),
                ],
            },
            Stage {
                name: "closed loop's logged tracker and ground truth".into(),
                requires: vec![],
                optional: vec![
                    p.follower_topic.clone(),
                    crate::groundtruth::PEOPLE_TOPIC.into(),
                ],
            },
        ]
    }

    fn process(
        s: &Session,
        p: &Params,
        _: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        session::process(s, p, bar)
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        aggregate::products(ctx, p)
    }
}
