//! `[robot.follow]`: the following robot's parameters — its target, following distance and
//! limits, and the closed loop's keys (`closed_loop`, `controllers`, `max_decel`,
//! `max_turn_rate`, `estimator`, `pdaf`, `platform`, `lost`; see `synth::follow`).

use serde::{Deserialize, Serialize};

use super::{MountFrame, SensorSpec};
use crate::laser::follow::FollowSpec;

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Follow {
    pub target: u32,
    pub distance: f64,
    pub max_speed: f64,
    pub max_accel: f64,
    /// Body pitch per m/s² of acceleration (a self-balancing base leans into acceleration).
    #[serde(default)]
    pub pitch_deg_per_mps2: f64,
    #[serde(default = "default_pitch_tau")]
    pub pitch_tau_s: f64,
    /// Drive the robot from a tracker's estimate at every scan (`synth::follow`) instead of
    /// from the target's true track. Off by default: open-loop datasets stay as they were.
    #[serde(default)]
    pub closed_loop: bool,
    /// Following controllers of the closed loop, cycled by session index.
    #[serde(default = "default_controllers")]
    pub controllers: Vec<Controller>,
    /// `a_min` of seed 001 (m/s²): the largest deceleration; `None`: `max_accel`.
    pub max_decel: Option<f64>,
    /// Turn-rate limit of the closed loop (rad/s).
    #[serde(default = "default_max_turn_rate")]
    pub max_turn_rate: f64,
    /// The target estimator that feeds the closed loop.
    #[serde(default)]
    pub estimator: Estimator,
    /// Settings of the `pdaf` estimator (every key optional; `laser::follow::FollowSpec`).
    #[serde(default)]
    pub pdaf: FollowSpec,
    /// The platform under the controllers: footprint and obstacle check
    /// (`synth::follow::avoid`).
    #[serde(default)]
    pub platform: Platform,
    /// What the robot does while the target is lost (`synth::follow::controller`).
    #[serde(default)]
    pub lost: Lost,
}

/// `[robot.follow.platform]`: the robot's footprint and its obstacle check.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Platform {
    /// Footprint radius (m): seed 001's "human-size footprint", 0.7 m across.
    pub radius_m: f64,
    /// Clearance the obstacle check keeps beyond the footprint (m).
    pub margin_m: f64,
    /// Run the obstacle check on the controllers' commands.
    pub avoid: bool,
}

impl Default for Platform {
    fn default() -> Self {
        Platform {
            radius_m: 0.35,
            margin_m: 0.15,
            avoid: true,
        }
    }
}

impl Follow {
    /// `a_min`: the largest deceleration (m/s²).
    pub fn decel(&self) -> f64 {
        self.max_decel.unwrap_or(self.max_accel)
    }
}

fn default_pitch_tau() -> f64 {
    0.3
}

fn default_max_turn_rate() -> f64 {
    1.5
}

fn default_controllers() -> Vec<Controller> {
    vec![Controller::Pursuit, Controller::Direct]
}

/// A following controller of seed 001 §VI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Controller {
    /// Pure pursuit along the person's estimated path.
    Pursuit,
    /// Minimise the relative bearing and the range error.
    Direct,
}

impl Controller {
    pub fn name(self) -> &'static str {
        match self {
            Controller::Pursuit => "pursuit",
            Controller::Direct => "direct",
        }
    }
}

/// What the closed loop's robot does while its estimator has lost the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Lost {
    /// Seed 001 §VI: `rst` "will cause the robot to stop"; it turns towards the target's
    /// last prediction while it stands.
    #[default]
    Stop,
    /// Our addition (issue 30, round 14): drive to the last prediction, then turn in place
    /// there (`synth::follow::controller::search`).
    Search,
}

/// The estimator of the target that the closed loop follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Estimator {
    /// The placeholder baseline: the laser return cluster nearest to the last estimate.
    #[default]
    NearestBlob,
    /// Seed 001's tracker (`laser::follow`: coordinated-turn PDAF with the colour
    /// likelihood), with `[robot.follow.pdaf]`'s settings.
    Pdaf,
}

/// The first problem of a `[robot.follow]` table's closed-loop keys or of its `pdaf` table:
/// `(key, reason)`.
pub(super) fn follow_problem(f: &Follow, sensors: &[SensorSpec]) -> Option<(String, String)> {
    if let Some((key, reason)) = f.pdaf.problems().into_iter().next() {
        return Some((format!("pdaf.{key}"), reason));
    }
    loop_problem(f, sensors).map(|(k, r)| (k.to_string(), r))
}

/// The first problem of a `[robot.follow]` table's closed-loop keys: `(key, reason)`.
fn loop_problem(f: &Follow, sensors: &[SensorSpec]) -> Option<(&'static str, String)> {
    if !(f.max_speed > 0.0 && f.max_accel > 0.0) {
        return Some((
            "max_speed",
            "max_speed and max_accel must be positive".into(),
        ));
    }
    if f.max_decel.is_some_and(|a| !(a > 0.0 && a.is_finite())) {
        return Some((
            "max_decel",
            format!("{:?} is not a positive deceleration", f.max_decel),
        ));
    }
    if !(f.max_turn_rate > 0.0 && f.max_turn_rate.is_finite()) {
        return Some((
            "max_turn_rate",
            format!("{} is not positive", f.max_turn_rate),
        ));
    }
    let pl = &f.platform;
    if !(pl.radius_m >= 0.0
        && pl.radius_m.is_finite()
        && pl.margin_m >= 0.0
        && pl.margin_m.is_finite())
    {
        return Some((
            "platform",
            format!(
                "radius_m {} and margin_m {} must be finite and ≥ 0",
                pl.radius_m, pl.margin_m
            ),
        ));
    }
    if f.controllers.is_empty() {
        return Some((
            "controllers",
            "name at least one of \"pursuit\", \"direct\"".into(),
        ));
    }
    let robot_laser = sensors
        .iter()
        .any(|x| matches!(x, SensorSpec::Laser { mount, .. } if mount.on == MountFrame::Robot));
    if f.closed_loop && !robot_laser {
        return Some((
            "closed_loop",
            "the closed loop needs a laser mounted on the robot".into(),
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(extra: &str) -> Follow {
        toml::from_str(&format!(
            "target = 1\ndistance = 1.8\nmax_speed = 2.0\nmax_accel = 1.0\n{extra}"
        ))
        .expect("parses")
    }

    #[test]
    fn closed_loop_keys_default_and_their_problems_name_the_key() {
        let f = parse("");
        assert!(!f.closed_loop);
        assert_eq!(f.controllers, vec![Controller::Pursuit, Controller::Direct]);
        assert_eq!(f.estimator, Estimator::NearestBlob);
        assert_eq!(f.decel(), 1.0);
        assert_eq!(follow_problem(&f, &[]), None);
        let key = |extra: &str| follow_problem(&parse(extra), &[]).map(|p| p.0);
        let key = |extra: &str| key(extra).map(|k| k.to_string());
        let some = |k: &str| Some(k.to_string());
        assert_eq!(key("controllers = []"), some("controllers"));
        assert_eq!(key("max_decel = -1.0"), some("max_decel"));
        assert_eq!(key("max_turn_rate = 0.0"), some("max_turn_rate"));
        // no laser on the robot to close the loop with
        assert_eq!(key("closed_loop = true"), some("closed_loop"));
        // the pdaf estimator's settings are checked and named under `pdaf.`
        assert_eq!(key("pdaf = { sigma_r = -1.0 }"), some("pdaf.sigma_r"));
        assert!(toml::from_str::<Follow>("target = 1\ndistance = 1.8\nmax_speed = 2.0\nmax_accel = 1.0\nestimator = \"pdaf2\"").is_err());
        assert!(toml::from_str::<Follow>("target = 1\ndistance = 1.8\nmax_speed = 2.0\nmax_accel = 1.0\ncontrollers = [\"wander\"]").is_err());
    }
}
