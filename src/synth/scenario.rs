//! Scenario files (`datasets/<name>/scenario.toml`): the world, the people and how they move,
//! the robot, and the sensors of one synthetic dataset, with `quick` and `full` profiles that
//! change the number of sessions and their length. Parsed strictly: unknown keys and wrong
//! types are errors with their line; out-of-range values name their key path.
//!
//! Units: metres, seconds, degrees in the file (`*_deg`), colours as `[r, g, b]` 0–255.
//! Coordinates are in the `map` frame, z up, the floor at z = 0.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

mod biron;
mod follow;
mod validate;
pub use biron::BironSpec;
use follow::follow_problem;
pub use follow::{Controller, Estimator, Follow, Lost, Platform};

#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    // `error`, not `source`: a source would be printed twice in an error chain
    #[error("cannot read scenario {path}: {error}")]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{path}: {message}")]
    Parse { path: PathBuf, message: String },
    #[error("{path}: `{key}`: {reason}")]
    Invalid {
        path: PathBuf,
        key: String,
        reason: String,
    },
    #[error("{path}: no profile `{profile}` (the file defines: {known})")]
    Profile {
        path: PathBuf,
        profile: String,
        known: String,
    },
}

pub type Rgb = [u8; 3];

fn one() -> f64 {
    1.0
}
fn default_sessions() -> u32 {
    1
}

/// `[scenario]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Meta {
    pub name: String,
    pub seed: u64,
    #[serde(default)]
    pub description: String,
    /// Paper the set-up follows.
    #[serde(default)]
    pub paper: String,
    #[serde(default = "default_sessions")]
    pub sessions: u32,
    pub duration_s: f64,
    /// Index of the first session (its seed streams and file name `<name>_NN`); later ones
    /// follow. A profile may start elsewhere so that its sessions are others than the quick
    /// profile's (a held-out set, a training split).
    #[serde(default)]
    pub first_session: u32,
}

/// `[profiles.<name>]`: what a profile changes.
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Profile {
    pub sessions: Option<u32>,
    pub duration_s: Option<f64>,
    /// The profile's sessions are `first_session`, `first_session + 1`, … (default: the
    /// scenario's, 0).
    pub first_session: Option<u32>,
    /// `[[profiles.<name>.people]]`: a scripted person's height per session in this profile
    /// only (e.g. several people's heights in the full profile while the quick one keeps one).
    #[serde(default)]
    pub people: Vec<PersonOverride>,
}

/// What a profile changes of one scripted person.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PersonOverride {
    /// The `[[people]]` entry's `id`.
    pub id: u32,
    /// Sets that person's `heights` (see [`PersonSpec::heights`]).
    pub heights: Vec<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WorldKind {
    /// Floor, four walls and a ceiling spanning `[0, size.x] × [0, size.y]`.
    Room,
    /// Ground plane and sky; `size` is the area people and the robot move in.
    Outdoor,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TextureSpec {
    #[default]
    Flat,
    /// Square tiles of `size` m, alternate tiles darkened by `contrast`.
    Tiles { size: f64, contrast: f64 },
    /// Smooth random variation of relative amplitude `amp` at scale `scale` m.
    Noise { scale: f64, amp: f64 },
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Surface {
    pub color: Rgb,
    #[serde(default)]
    pub texture: TextureSpec,
}

/// A static box (desk, cupboard, box, wall segment).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// Centre of the footprint on the floor `[x, y]`; the box stands on the floor.
    pub at: [f64; 2],
    /// `[length x, depth y, height z]`.
    pub size: [f64; 3],
    #[serde(default)]
    pub yaw_deg: f64,
    pub color: Rgb,
    #[serde(default)]
    pub texture: TextureSpec,
    /// Height of the bottom above the floor (desk tops on thin legs: the laser sees under them).
    #[serde(default)]
    pub raised: f64,
}

/// Trees and bushes scattered at random over the area, avoiding `keep_clear` discs.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scatter {
    pub trees: u32,
    pub bushes: u32,
    #[serde(default)]
    pub keep_clear: Vec<[f64; 3]>,
}

/// Leg-like clutter for laser scenes (`[world.clutter]`; see `synth::world::clutter`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clutter {
    /// Where it stands `[x0, y0, x1, y1]`.
    pub area: [f64; 4],
    /// Thin vertical poles and their radius range (m).
    #[serde(default)]
    pub poles: u32,
    #[serde(default = "default_pole_radius")]
    pub pole_radius: [f64; 2],
    /// Tree trunks (no crown) and their radius range (m).
    #[serde(default)]
    pub trunks: u32,
    #[serde(default = "default_trunk_radius")]
    pub trunk_radius: [f64; 2],
    /// Tables on four legs, chairs on four legs, walls with one or two gaps.
    #[serde(default)]
    pub tables: u32,
    #[serde(default)]
    pub chairs: u32,
    #[serde(default)]
    pub walls: u32,
    /// Discs `[x, y, r]` kept free.
    #[serde(default)]
    pub keep_clear: Vec<[f64; 3]>,
}

fn default_pole_radius() -> [f64; 2] {
    [0.015, 0.05]
}
fn default_trunk_radius() -> [f64; 2] {
    [0.08, 0.2]
}

/// An opening people enter and leave by (a darker rectangle on the wall).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Door {
    pub at: [f64; 2],
    #[serde(default = "one")]
    pub width: f64,
}

/// Background that moves but is not a person.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum DynamicSpec {
    /// A monitor with rolling interference bars.
    Monitor {
        at: [f64; 3],
        size: [f64; 2],
        yaw_deg: f64,
        color: Rgb,
        bar_period_s: f64,
    },
    /// A plant swaying in the wind.
    Plant {
        at: [f64; 2],
        height: f64,
        radius: f64,
        color: Rgb,
        sway_m: f64,
        period_s: f64,
    },
    /// Vehicles passing behind a window: boxes moving along x at `y`.
    Traffic {
        y: f64,
        x_range: [f64; 2],
        speed: f64,
        every_s: f64,
        size: [f64; 3],
    },
}

/// Region with its own light level (a robot visiting places of different illumination).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Place {
    pub at: [f64; 2],
    pub radius: f64,
    pub level: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    #[serde(default = "one")]
    pub level: f64,
    /// Share of light that is ambient (the rest comes from the sun/ceiling direction).
    #[serde(default = "default_ambient")]
    pub ambient: f64,
    /// Relative amplitude and period of a slow drift of the level.
    #[serde(default)]
    pub drift: f64,
    #[serde(default = "default_drift_period")]
    pub drift_period_s: f64,
    /// Sudden switches `[time_s, new level]`.
    #[serde(default)]
    pub switches: Vec<[f64; 2]>,
    #[serde(default)]
    pub places: Vec<Place>,
}

fn default_ambient() -> f64 {
    0.55
}
fn default_drift_period() -> f64 {
    120.0
}

impl Default for Light {
    fn default() -> Self {
        Light {
            level: 1.0,
            ambient: default_ambient(),
            drift: 0.0,
            drift_period_s: default_drift_period(),
            switches: Vec::new(),
            places: Vec::new(),
        }
    }
}

/// `[world]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    pub kind: WorldKind,
    pub size: [f64; 2],
    #[serde(default = "default_wall_height")]
    pub wall_height: f64,
    pub floor: Surface,
    pub walls: Option<Surface>,
    #[serde(default)]
    pub boxes: Vec<BoxSpec>,
    pub scatter: Option<Scatter>,
    /// Leg-like clutter for laser scenes (absent: none).
    #[serde(default)]
    pub clutter: Option<Clutter>,
    #[serde(default)]
    pub doors: Vec<Door>,
    #[serde(default)]
    pub dynamic: Vec<DynamicSpec>,
    #[serde(default)]
    pub light: Light,
}

fn default_wall_height() -> f64 {
    2.8
}

/// How a person moves.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Motion {
    /// Walk through `points` at `speed`, pausing `pause_s` at each; `repeat` loops the list.
    Waypoints {
        points: Vec<[f64; 2]>,
        speed: f64,
        #[serde(default)]
        pause_s: f64,
        #[serde(default)]
        repeat: bool,
    },
    /// Random walk between random points of `area` (`[x0, y0, x1, y1]`), avoiding obstacles.
    Wander {
        area: [f64; 4],
        speed: [f64; 2],
        #[serde(default)]
        pause_s: [f64; 2],
        /// Where the walk starts (`[x, y]`); absent: a random point of `area` per session.
        #[serde(default)]
        start: Option<[f64; 2]>,
    },
    /// A cooperating runner's route (`synth::motion::jog`): straight stretches of `stretch_m`
    /// at a pace from `speed`, clear of trees and bushes by `clearance_m`, inside `area`, each
    /// turning by at most `max_turn_deg`; heading rate bounded by `lateral_accel / v`, pace
    /// changes at `accel`. Starts at `start` heading `heading_deg` (absent: random).
    Jog {
        area: [f64; 4],
        speed: [f64; 2],
        stretch_m: [f64; 2],
        #[serde(default = "default_max_turn_deg")]
        max_turn_deg: f64,
        #[serde(default = "default_lateral_accel")]
        lateral_accel: f64,
        #[serde(default = "default_jog_accel")]
        accel: f64,
        #[serde(default = "default_clearance")]
        clearance_m: f64,
        start: Option<[f64; 2]>,
        heading_deg: Option<f64>,
    },
    /// Replay a real trajectory (`frame id x y` at 2.5 Hz, e.g. ../shared/real/eth_ucy/*.txt),
    /// moved by `offset` and turned by `rotate_deg`.
    Replay {
        file: String,
        track: u32,
        #[serde(default)]
        offset: [f64; 2],
        #[serde(default)]
        rotate_deg: f64,
    },
}

fn default_max_turn_deg() -> f64 {
    90.0
}
fn default_lateral_accel() -> f64 {
    2.0
}
fn default_jog_accel() -> f64 {
    1.0
}
fn default_clearance() -> f64 {
    0.6
}

/// `[[people]]`: one scripted person.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PersonSpec {
    pub id: u32,
    pub height: f64,
    /// Height per session instead of `height`: session k has `heights[k mod len]` (the same
    /// walk, motion and colours; only the body's size differs). Absent: `height` everywhere.
    #[serde(default)]
    pub heights: Option<Vec<f64>>,
    /// Body (shoulder) radius.
    #[serde(default = "default_width")]
    pub width: f64,
    #[serde(default = "default_leg")]
    pub leg_radius: f64,
    pub upper: Rgb,
    pub lower: Rgb,
    #[serde(default = "default_skin")]
    pub skin: Rgb,
    #[serde(default = "default_hair")]
    pub hair: Rgb,
    pub hat: Option<Rgb>,
    /// Render skin-coloured hands (seed 002's skin detection). Off by default so that other
    /// datasets render exactly as before.
    #[serde(default)]
    pub hands: bool,
    /// Present from `enter_s` to `leave_s` (seconds from the session start).
    #[serde(default)]
    pub enter_s: f64,
    pub leave_s: Option<f64>,
    /// Present during this share of the session instead, e.g. `[0.5, 1.0]` for its second half
    /// (keeps working when a profile changes the duration).
    pub share: Option<[f64; 2]>,
    pub motion: Motion,
}

impl PersonSpec {
    /// The person's height in session `session` (see `heights`).
    pub fn height_in(&self, session: u64) -> f64 {
        match &self.heights {
            Some(h) if !h.is_empty() => h[(session % h.len() as u64) as usize],
            _ => self.height,
        }
    }
}

fn default_width() -> f64 {
    0.2
}
fn default_leg() -> f64 {
    0.065
}
fn default_skin() -> Rgb {
    [214, 160, 130]
}
fn default_hair() -> Rgb {
    [60, 42, 30]
}

/// `[variation]`: what makes one session's visitors unlike another's, besides the random
/// streams of their walks. From session `from_session` on, every scripted person's top, trousers
/// and hair are drawn from the synthesizer's clothing palette (`clothes`; the tops all
/// different within a session, as visitors a robot should tell apart), and a random number in
/// `absent` (inclusive) of them stay away. Earlier sessions keep the cast as written.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variation {
    pub from_session: u32,
    #[serde(default)]
    pub clothes: bool,
    #[serde(default)]
    pub absent: [u32; 2],
}

/// `[crowd]`: people generated at random — visitors coming through doors, passers-by.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Crowd {
    pub count: u32,
    /// Area they walk in `[x0, y0, x1, y1]`.
    pub area: [f64; 4],
    /// Time each is present (s).
    pub stay_s: [f64; 2],
    pub speed: [f64; 2],
    #[serde(default = "default_heights")]
    pub height: [f64; 2],
    /// Enter and leave by the world's doors.
    #[serde(default)]
    pub use_doors: bool,
    /// Cross the line between the robot and this person (outdoor following).
    pub cross_between_robot_and: Option<u32>,
    /// Of those, how many (the first ones) first run beside that person, then cross between
    /// the robot and them (`synth::motion::jog::companion`).
    #[serde(default)]
    pub companions: u32,
    /// Leg radius range (m) of the crowd's people; absent: 0.055–0.075.
    #[serde(default)]
    pub leg_radius: Option<[f64; 2]>,
}

fn default_heights() -> [f64; 2] {
    [1.55, 1.95]
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RobotMode {
    Static,
    /// Follow a person along their path (pure pursuit), pitching when accelerating.
    Follow,
    /// Drive between stops, dwelling at each.
    Tour,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tour {
    /// `[x, y, yaw_deg]` stops.
    pub stops: Vec<[f64; 3]>,
    pub dwell_s: f64,
    pub speed: f64,
}

/// `[robot]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Robot {
    pub mode: RobotMode,
    /// Start pose `[x, y, yaw_deg]`.
    pub pose: [f64; 3],
    pub follow: Option<Follow>,
    pub tour: Option<Tour>,
    /// Odometry noise: relative speed error and yaw-rate noise (rad/s).
    #[serde(default = "default_odom_noise")]
    pub odom_noise: [f64; 2],
    #[serde(default = "default_odom_rate")]
    pub odom_rate_hz: f64,
    #[serde(default = "default_imu_rate")]
    pub imu_rate_hz: f64,
}

fn default_odom_noise() -> [f64; 2] {
    [0.02, 0.01]
}
fn default_odom_rate() -> f64 {
    50.0
}
fn default_imu_rate() -> f64 {
    100.0
}

/// Where a sensor sits: on the robot (`base_link`) or fixed in the world (`map`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mount {
    pub on: MountFrame,
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw of the sensor body (x forward, z up) in degrees.
    #[serde(default)]
    pub rpy_deg: [f64; 3],
    /// Point a world-mounted pinhole at this point instead of using `rpy_deg`.
    pub look_at: Option<[f64; 3]>,
    /// Random error of a world-mounted camera's true pose around the nominal one:
    /// `[position m, heading deg]` (the calibration pipeline must recover it).
    pub perturb: Option<[f64; 2]>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MountFrame {
    Robot,
    World,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ImageFormat {
    /// `sensor_msgs/Image` rgb8.
    Raw,
    /// `sensor_msgs/CompressedImage` JPEG (quality `jpeg_quality`).
    Jpeg,
}

/// Common camera settings.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraCommon {
    pub name: String,
    pub mount: Mount,
    pub rate_hz: f64,
    pub width: u32,
    pub height: u32,
    /// Sensor noise, standard deviation in 8-bit units.
    #[serde(default = "default_noise")]
    pub noise: f64,
    #[serde(default = "default_format")]
    pub format: ImageFormat,
    #[serde(default = "default_quality")]
    pub jpeg_quality: u8,
    /// Also publish the exact person mask `/<name>/ground_truth_mask`.
    #[serde(default)]
    pub mask: bool,
    /// Also publish the exact skin mask `/<name>/ground_truth_skin` (face, neck, hands: what
    /// seed 002's skin histogram is trained and scored on).
    #[serde(default)]
    pub skin_mask: bool,
    /// Also publish whose pixel each pixel is, `/<name>/ground_truth_ids` (`mono8`: the person's
    /// id, 0 where no person is seen, 255 for ids of 255 and above): a per-person exact mask.
    #[serde(default)]
    pub id_mask: bool,
}

fn default_noise() -> f64 {
    2.0
}
fn default_format() -> ImageFormat {
    ImageFormat::Jpeg
}
fn default_quality() -> u8 {
    92
}

/// `[[sensors]]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SensorSpec {
    Pinhole {
        #[serde(flatten)]
        camera: CameraCommon,
        hfov_deg: f64,
        /// plumb_bob k1, k2, p1, p2, k3.
        #[serde(default)]
        distortion: [f64; 5],
    },
    Paracatadioptric {
        #[serde(flatten)]
        camera: CameraCommon,
        f: f64,
        r_min: f64,
        r_max: f64,
    },
    Conical {
        #[serde(flatten)]
        camera: CameraCommon,
        f: f64,
        apex_m: f64,
        alpha_deg: f64,
        top_m: f64,
    },
    Laser {
        name: String,
        mount: Mount,
        rate_hz: f64,
        fov_deg: f64,
        resolution_deg: f64,
        range_min: f64,
        range_max: f64,
        #[serde(default = "default_range_noise")]
        noise_m: f64,
        /// Probability that a beam returns nothing (written as NaN).
        #[serde(default)]
        dropout: f64,
        #[serde(default = "default_scan_topic")]
        topic: String,
    },
}

fn default_range_noise() -> f64 {
    0.01
}
fn default_scan_topic() -> String {
    "/scan".into()
}

impl SensorSpec {
    pub fn name(&self) -> &str {
        match self {
            SensorSpec::Pinhole { camera, .. }
            | SensorSpec::Paracatadioptric { camera, .. }
            | SensorSpec::Conical { camera, .. } => &camera.name,
            SensorSpec::Laser { name, .. } => name,
        }
    }

    pub fn rate_hz(&self) -> f64 {
        match self {
            SensorSpec::Pinhole { camera, .. }
            | SensorSpec::Paracatadioptric { camera, .. }
            | SensorSpec::Conical { camera, .. } => camera.rate_hz,
            SensorSpec::Laser { rate_hz, .. } => *rate_hz,
        }
    }
}

/// `[calibration]`: a segment at the start where a person stands on known marks.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    pub person: u32,
    pub positions: Vec<[f64; 2]>,
    pub dwell_s: f64,
    #[serde(default = "default_walk_speed")]
    pub speed: f64,
}

fn default_walk_speed() -> f64 {
    0.8
}

/// A whole scenario file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    pub scenario: Meta,
    #[serde(default)]
    pub profiles: BTreeMap<String, Profile>,
    pub world: World,
    #[serde(default)]
    pub people: Vec<PersonSpec>,
    pub crowd: Option<Crowd>,
    pub variation: Option<Variation>,
    pub robot: Robot,
    #[serde(default)]
    pub sensors: Vec<SensorSpec>,
    pub calibration: Option<Calibration>,
    /// Seed 003's BIRON home tour, written by `synth::biron` (issue 33).
    pub biron: Option<BironSpec>,
}

impl Scenario {
    /// Read, parse and validate a scenario, applying `profile` (`quick`, `full`, ...).
    pub fn load(path: &Path, profile: &str) -> Result<(Scenario, String), ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|error| ScenarioError::Read {
            path: path.to_path_buf(),
            error,
        })?;
        let mut s: Scenario = toml::from_str(&text).map_err(|e| ScenarioError::Parse {
            path: path.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
        let p = s
            .profiles
            .get(profile)
            .cloned()
            .ok_or_else(|| ScenarioError::Profile {
                path: path.to_path_buf(),
                profile: profile.to_string(),
                known: s.profiles.keys().cloned().collect::<Vec<_>>().join(", "),
            })?;
        if let Some(n) = p.sessions {
            s.scenario.sessions = n;
        }
        if let Some(d) = p.duration_s {
            s.scenario.duration_s = d;
        }
        if let Some(f) = p.first_session {
            s.scenario.first_session = f;
        }
        for (i, o) in p.people.iter().enumerate() {
            let Some(person) = s.people.iter_mut().find(|q| q.id == o.id) else {
                return Err(ScenarioError::Invalid {
                    path: path.to_path_buf(),
                    key: format!("profiles.{profile}.people[{i}].id"),
                    reason: format!("no [[people]] entry with id {}", o.id),
                });
            };
            person.heights = Some(o.heights.clone());
        }
        let dur = s.scenario.duration_s;
        for person in &mut s.people {
            if let Some([a, b]) = person.share {
                person.enter_s = a * dur;
                person.leave_s = Some(b * dur);
            }
        }
        s.validate()
            .map_err(|(key, reason)| ScenarioError::Invalid {
                path: path.to_path_buf(),
                key,
                reason,
            })?;
        Ok((s, text))
    }
}
