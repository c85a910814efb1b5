//! `[params]` of `pipelines/s001_kobilarov_following.toml` and their validation. The paper
//! gives no filter or detector values; the defaults of [`FollowSpec`] were set a priori (see
//! `laser::follow` and `track::pdaf`), never searched against the numbers the pipeline reports.

use serde::{Deserialize, Serialize};

use crate::laser::follow::FollowSpec;
use crate::run::config::Invalid;
use crate::track::pdaf::{AssociationKind, ModelKind};
use crate::vision::egomotion::Method1Params;

/// A real laser log run laser-only (no camera in it): its topics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RealSequence {
    /// The log's file stem.
    pub name: String,
    pub scan_topic: String,
    /// `leg_tracker/msg/Person` annotations (laser frame).
    pub gt_topic: String,
}

/// `[params]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    pub scan_topic: String,
    pub camera: String,
    /// The closed loop's logged tracker output (JSON, `peopletrack.FollowerState`).
    pub follower_topic: String,
    /// Ground-truth id of the followed person.
    pub target_id: u32,
    /// The frame the robot tracked in (its odometry), the robot's own frame, and the IMU
    /// whose roll and pitch tilt it (§III: pitch and roll from the gyros).
    pub fixed_frame: String,
    pub base_frame: String,
    pub imu_topic: String,
    /// Ground truth joined to a scan by nearest stamp within this (s).
    pub gt_tolerance_s: f64,
    /// The robot's following distance d_follow (m) and maximum deceleration a_min (m/s²) of
    /// E_follow = r − d_follow − v²/(2 a_min): the closed loop's controller settings.
    pub following_distance_m: f64,
    pub max_decel_mps2: f64,
    /// Methods replayed on every log, in table order (see [`method`]).
    pub methods: Vec<String>,
    /// The replayed method that is the closed loop's own configuration (the scenario's
    /// `[robot.follow] pdaf` settings): `replay_check` compares it with the loop's logged
    /// estimates, and the `rst` causes use its last accepted measurement. One of `methods`.
    pub loop_method: String,
    pub follower: FollowSpec,
    /// Weight of the newest histogram in the updated template (`ct_colour_updated`), per scan
    /// with an association.
    pub template_update: f64,
    /// The colour watchdog's time for `ct_colour_watch` (s; our addition, chosen on the `dev`
    /// profile).
    pub colour_watch_s: f64,
    /// A person within this distance (m, beyond their radius) of the laser's line of sight to
    /// the target, and nearer than it, occludes it.
    pub occlusion_margin_m: f64,
    /// An estimate within this distance (m) of a person is locked on that person.
    pub lock_m: f64,
    /// Window after an occlusion over which the models' errors are compared (s).
    pub after_occlusion_s: f64,
    /// "Followed" (decided before the full run): the robot's own estimate within
    /// `followed_within_m` of the true person on at least `followed_share` of the run's scans,
    /// and the robot within `followed_end_m` of the person at the run's end.
    pub followed_within_m: f64,
    pub followed_share: f64,
    pub followed_end_m: f64,
    /// Occlusions shorter than this are not events (s).
    pub min_occlusion_s: f64,
    /// Method 1: lost when the bearing is farther than this from the truth (deg), and the
    /// speed bins of its loss rate (m/s).
    pub method1_lost_deg: f64,
    pub method1_speed_bin: f64,
    /// Every `method1_every`-th omni frame is processed by method 1 (1: all).
    pub method1_every: usize,
    pub method1: Method1Params,
    /// Figures: the fig. 7 window length (s).
    pub fig7_window_s: f64,
    pub level: f64,
    /// Real laser logs (laser only), matched by file stem; SKIPPED when absent.
    pub real: Vec<RealSequence>,
    /// Real logs are scored within this distance of the annotation (m; the authors'
    /// clear_mot.py threshold).
    pub real_match_m: f64,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            scan_topic: "/scan".into(),
            camera: "omni_camera".into(),
            follower_topic: "/follower/state".into(),
            target_id: 1,
            fixed_frame: "odom".into(),
            base_frame: "base_link".into(),
            imu_topic: "/imu".into(),
            gt_tolerance_s: 0.06,
            following_distance_m: 3.2,
            max_decel_mps2: 1.4,
            methods: METHODS.iter().map(|m| (*m).to_string()).collect(),
            loop_method: PAPER.into(),
            follower: FollowSpec::default(),
            template_update: 0.05,
            colour_watch_s: 1.0,
            occlusion_margin_m: 0.1,
            lock_m: 0.5,
            after_occlusion_s: 2.0,
            followed_within_m: 1.0,
            followed_share: 0.95,
            followed_end_m: 6.0,
            min_occlusion_s: 0.3,
            method1_lost_deg: 15.0,
            method1_speed_bin: 0.5,
            method1_every: 1,
            method1: Method1Params::default(),
            fig7_window_s: 30.0,
            level: 0.95,
            real: Vec::new(),
            real_match_m: 0.75,
        }
    }
}

/// A configuration of `laser::follow`'s follower, as a replayed method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variant {
    pub model: ModelKind,
    pub association: AssociationKind,
    pub colour: bool,
    /// The colour template follows the target (`template_update` per scan) instead of
    /// staying as taken at initialisation.
    pub update: bool,
    /// corr as printed (no square root) instead of the normalised form.
    pub printed: bool,
    /// `rst` at the paper's literal "usually 5" σ_r
    /// ([`crate::track::pdaf::RESET_SIGMAS_LITERAL`]) instead of the multiplier derived from
    /// its reset timing (`follower.reset_sigmas`).
    pub literal_rst: bool,
    /// The colour watchdog (our addition, `laser::follow::FollowParams::colour_watch_s`) at
    /// `colour_watch_s`.
    pub colour_watch: bool,
    /// The other people tracked, their blobs discounted (our addition,
    /// `laser::follow::others`).
    pub others: bool,
    /// Ground hits make no blob (`laser::follow::FollowParams::ground_below_m` at
    /// [`GROUND_BELOW_M`]; our reading of §VI).
    pub ground: bool,
}

impl Variant {
    /// The paper's configuration: coordinated turn, PDAF, colour, template held.
    pub const PAPER: Variant = Variant {
        model: ModelKind::Ct,
        association: AssociationKind::Pdaf,
        colour: true,
        update: false,
        printed: false,
        literal_rst: false,
        colour_watch: false,
        ground: false,
        others: false,
    };
}

/// One replayed method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// The follower of `laser::follow`.
    Follower(Variant),
    /// The laser issue's multi-person tracker (`laser::tracker`), its track nearest the
    /// target followed.
    LaserTracker,
}

/// The paper's configuration: coordinated turn, PDAF, colour.
pub const PAPER: &str = "ct_colour";
/// The same with the template updated while tracking (the paper allows both).
pub const UPDATED: &str = "ct_colour_updated";
/// The same with corr as printed (Σ H_i H_j / (Σ H_i² Σ H_j²), no square root).
pub const PRINTED: &str = "ct_colour_printed";
/// The same with `rst` when √λ_max(P_xy) > 5 σ_r, the paper's "usually 5" read literally.
pub const RST5: &str = "ct_colour_rst5";
/// Our addition: the paper's configuration with the colour watchdog (`colour_watch_s`).
pub const WATCH: &str = "ct_colour_watch";
/// Our addition: the paper's configuration with the other people tracked
/// (`laser::follow::others`).
pub const OTHERS: &str = "ct_colour_others";
/// Our reading of §VI ("no valid measurements of the human" while the laser sees the ground)
/// on top of the colour watchdog: returns below [`GROUND_BELOW_M`] make no blob.
pub const WATCH_GROUND: &str = "ct_colour_watch_ground";
/// The ground's height in `odom` (m): the platform check's `synth::follow::avoid::GROUND_Z_M`,
/// a priori.
pub const GROUND_BELOW_M: f64 = 0.1;
pub const CV: &str = "cv_colour";
pub const IMM: &str = "imm_colour";
pub const NO_COLOUR: &str = "ct_no_colour";
pub const NN: &str = "nn_ct";
pub const LASER_TRACKER: &str = "laser_tracker";
/// Every known method, in the default table order.
pub const METHODS: [&str; 12] = [
    PAPER,
    UPDATED,
    PRINTED,
    RST5,
    WATCH,
    WATCH_GROUND,
    OTHERS,
    CV,
    IMM,
    NO_COLOUR,
    NN,
    LASER_TRACKER,
];

/// The method a name stands for.
pub fn method(name: &str) -> Option<Method> {
    use AssociationKind::Nearest;
    use ModelKind::{Cv, Imm};
    let p = Variant::PAPER;
    let v = match name {
        PAPER => p,
        UPDATED => Variant { update: true, ..p },
        PRINTED => Variant { printed: true, ..p },
        RST5 => Variant {
            literal_rst: true,
            ..p
        },
        WATCH => Variant {
            colour_watch: true,
            ..p
        },
        WATCH_GROUND => Variant {
            colour_watch: true,
            ground: true,
            ..p
        },
        OTHERS => Variant { others: true, ..p },
        CV => Variant { model: Cv, ..p },
        IMM => Variant { model: Imm, ..p },
        NO_COLOUR => Variant { colour: false, ..p },
        NN => Variant {
            association: Nearest,
            colour: false,
            ..p
        },
        LASER_TRACKER => return Some(Method::LaserTracker),
        _ => return None,
    };
    Some(Method::Follower(v))
}

impl Params {
    /// The real sequence a session is, by file stem.
    pub fn real_sequence(&self, stem: &str) -> Option<&RealSequence> {
        self.real.iter().find(|r| r.name == stem)
    }
}

pub(super) fn validate(p: &Params) -> Vec<Invalid> {
    let mut out: Vec<Invalid> = Vec::new();
    for (k, v) in [
        ("colour_watch_s", p.colour_watch_s),
        ("gt_tolerance_s", p.gt_tolerance_s),
        ("following_distance_m", p.following_distance_m),
        ("max_decel_mps2", p.max_decel_mps2),
        ("lock_m", p.lock_m),
        ("after_occlusion_s", p.after_occlusion_s),
        ("followed_within_m", p.followed_within_m),
        ("followed_end_m", p.followed_end_m),
        ("method1_lost_deg", p.method1_lost_deg),
        ("method1_speed_bin", p.method1_speed_bin),
        ("fig7_window_s", p.fig7_window_s),
        ("real_match_m", p.real_match_m),
    ] {
        if !(v.is_finite() && v > 0.0) {
            out.push((k.into(), format!("{v} must be finite and > 0")));
        }
    }
    for (k, v) in [
        ("occlusion_margin_m", p.occlusion_margin_m),
        ("min_occlusion_s", p.min_occlusion_s),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            out.push((k.into(), format!("{v} must be finite and >= 0")));
        }
    }
    if !(p.template_update > 0.0 && p.template_update <= 1.0) {
        out.push((
            "template_update".into(),
            format!("{} is not in (0, 1]", p.template_update),
        ));
    }
    if !(p.followed_share > 0.0 && p.followed_share <= 1.0) {
        out.push((
            "followed_share".into(),
            format!("{} is not in (0, 1]", p.followed_share),
        ));
    }
    if !(p.level > 0.0 && p.level < 1.0) {
        out.push(("level".into(), format!("{} is not in (0, 1)", p.level)));
    }
    if p.method1_every == 0 {
        out.push(("method1_every".into(), "0 must be >= 1".into()));
    }
    if p.methods.is_empty() {
        out.push((
            "methods".into(),
            "is empty: name at least one method".into(),
        ));
    }
    for m in &p.methods {
        if method(m).is_none() {
            out.push((
                "methods".into(),
                format!("unknown method {m:?} (known: {})", METHODS.join(", ")),
            ));
        }
    }
    if !p.methods.contains(&p.loop_method) {
        out.push((
            "loop_method".into(),
            format!(
                "{:?} is not one of `methods` (the closed loop's configuration must be replayed)",
                p.loop_method
            ),
        ));
    }
    for (k, reason) in p.follower.problems() {
        out.push((format!("follower.{k}"), reason));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every method name resolves, the defaults validate, and a loop method that is not
    /// replayed is refused by name.
    #[test]
    fn methods_resolve_and_the_loop_method_must_be_replayed() {
        assert!(METHODS.iter().all(|m| method(m).is_some()));
        assert_eq!(
            method(OTHERS),
            Some(Method::Follower(Variant {
                others: true,
                ..Variant::PAPER
            }))
        );
        assert!(validate(&Params::default()).is_empty());
        let p = Params {
            methods: vec![PAPER.into()],
            loop_method: OTHERS.into(),
            ..Params::default()
        };
        let problems = validate(&p);
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert_eq!(problems[0].0, "loop_method");
    }
}
