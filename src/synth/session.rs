//! One synthetic session, end to end: people and robot trajectories, then every sensor at its
//! own rate in time order — images (raw or JPEG) with `CameraInfo`, exact person masks, laser
//! scans, odometry, IMU, TF — plus ground truth, written as a ROS 2 MCAP like a real recording.
//!
//! Clocks: a sensor's header stamp is its capture time; the log time adds a small transport
//! latency (cameras 8–25 ms, laser 3–8 ms), so logs show the stamp-vs-log offsets real logs
//! do. Ground truth is stamped and logged at capture time.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::progress::Progress;
use image::RgbImage;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rand::RngExt;
use serde::Serialize;

use super::laser::{LaserSpec, scan};
use super::motion::{self, Goal, Track};
use super::person::{Body, PersonState};
use super::render::{Camera, FrameInput};
use super::robot::{self, RobotTrack};
use super::scenario::{
    ImageFormat, Motion, MountFrame, PersonSpec, RobotMode, Scenario, SensorSpec,
};
use super::world::{PERSON_BASE, Primitive, World};
use crate::geometry::camera::{ConicalMirror, Paracatadioptric, Pinhole};
use crate::geometry::{self, camera::CameraModel};
use crate::groundtruth::{self, CameraView, PeopleFrame, PersonTruth, Target, TargetsFrame};
use crate::log::msgs::{
    CameraInfo, CompressedImage, Header, Image, Imu, LaserScan, Odometry, Pose, TfMessage,
    Transform, TransformStamped,
};
use crate::log::{ChannelId, LogError, SessionWriter, WriterOptions};
use crate::rng;
use crate::time::Nanos;

/// Version of the generator, recorded in every log's metadata.
pub const GENERATOR_VERSION: &str =
    concat!("peopletrack-synth ", env!("CARGO_PKG_VERSION"), " (1)");

/// Epoch of session 0 (s); each session starts 10 000 s later.
const EPOCH_S: u64 = 1_700_000_000;

#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("{0}")]
    Scenario(String),
    #[error("encoding a frame of {camera}: {reason}")]
    Encode { camera: String, reason: String },
}

/// A person in a session: body and motion.
pub struct Actor {
    pub body: Body,
    pub track: Track,
}

enum SensorRuntime {
    Camera {
        cam: Box<Camera>,
        frame_id: String,
        /// `base_from_sensor` for robot-mounted, `map_from_sensor` for fixed.
        mount: Isometry3<f64>,
        on_robot: bool,
        rate: f64,
        format: ImageFormat,
        quality: u8,
        mask: bool,
        channels: (ChannelId, ChannelId, Option<ChannelId>),
    },
    Laser {
        spec: LaserSpec,
        frame_id: String,
        mount: Isometry3<f64>,
        on_robot: bool,
        rate: f64,
        channel: ChannelId,
    },
}

impl SensorRuntime {
    fn rate(&self) -> f64 {
        match self {
            SensorRuntime::Camera { rate, .. } | SensorRuntime::Laser { rate, .. } => *rate,
        }
    }
}

/// One camera's frame for the preview and what it saw of each person `(id, view)`.
pub type PreviewCamera = (String, RgbImage, Vec<(u32, CameraView)>);

/// What the preview sheet shows: one instant of the session.
pub struct PreviewData {
    pub t: f64,
    pub cameras: Vec<PreviewCamera>,
    /// Laser returns in the map frame.
    pub scan_points: Vec<[f64; 2]>,
    pub people: Vec<PersonTruth>,
    pub robot: [f64; 3],
    pub sensors: Vec<(String, [f64; 3])>,
    pub world: World,
}

/// Deterministic latency (ns) of a message.
fn latency(seed: u64, sensor: usize, k: u64, lo_ms: f64, hi_ms: f64) -> u64 {
    let u = f64::from(rng::unit(rng::hash(seed, &[0x1a7e, sensor as u64, k])));
    ((lo_ms + (hi_ms - lo_ms) * u) * 1e6) as u64
}

fn random_color(r: &mut rand_chacha::ChaCha8Rng) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 14] = [
        [180, 40, 40],
        [40, 70, 160],
        [30, 30, 35],
        [230, 230, 225],
        [200, 170, 60],
        [60, 120, 70],
        [120, 60, 140],
        [210, 120, 40],
        [90, 90, 95],
        [150, 180, 210],
        [120, 80, 50],
        [240, 200, 200],
        [20, 90, 100],
        [170, 40, 100],
    ];
    PALETTE[r.random_range(0..PALETTE.len())]
}

fn skin_tone(r: &mut rand_chacha::ChaCha8Rng) -> [u8; 3] {
    const SKIN: [[u8; 3]; 5] = [
        [232, 190, 160],
        [214, 160, 130],
        [180, 130, 95],
        [140, 95, 65],
        [100, 70, 50],
    ];
    SKIN[r.random_range(0..SKIN.len())]
}

/// A calibration target is published while the calibration person stands still within this
/// distance (m) of a mark; walkers stop up to `0.05 + v·dt` short of a goal, so 5 cm was too tight.
/// The published position is where the hat really is, not the mark.
const CALIBRATION_MARK_RADIUS: f64 = 0.15;

/// Motion of a scripted person, with the calibration walk first when it is theirs.
fn scripted_track(
    s: &Scenario,
    p: &PersonSpec,
    world: &World,
    base: &Path,
    session: u64,
) -> Result<Track, SynthError> {
    let dur = s.scenario.duration_s;
    let leave = p.leave_s.unwrap_or(dur).min(dur);
    let mut r = rng::stream(s.scenario.seed, &format!("person{}", p.id), session);
    let mut goals: Vec<Goal> = Vec::new();
    let mut start = None;
    if let Some(c) = s.calibration.as_ref().filter(|c| c.person == p.id) {
        for at in &c.positions {
            goals.push(Goal {
                x: at[0],
                y: at[1],
                speed: c.speed,
                pause: c.dwell_s,
            });
        }
        start = c.positions.first().map(|a| (a[0], a[1], 0.0));
    }
    match &p.motion {
        Motion::Waypoints {
            points,
            speed,
            pause_s,
            repeat,
        } => {
            let mut list: Vec<Goal> = points
                .iter()
                .map(|q| Goal {
                    x: q[0],
                    y: q[1],
                    speed: *speed,
                    pause: *pause_s,
                })
                .collect();
            if *repeat {
                let lap: f64 = points
                    .windows(2)
                    .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
                    .sum::<f64>()
                    / speed
                    + pause_s * points.len() as f64;
                let laps = ((leave - p.enter_s) / lap.max(1.0)).ceil() as usize + 1;
                list = list
                    .iter()
                    .cycle()
                    .take(list.len() * laps)
                    .copied()
                    .collect();
            }
            let first = (points[0][0], points[0][1], 0.0);
            goals.extend(list);
            Ok(motion::walk(
                start.unwrap_or(first),
                &goals,
                p.enter_s,
                leave,
                &mut r,
            ))
        }
        Motion::Wander {
            area,
            speed,
            pause_s,
        } => {
            let from = start.map(|s| (s.0, s.1)).unwrap_or((
                area[0] + r.random::<f64>() * (area[2] - area[0]),
                area[1] + r.random::<f64>() * (area[3] - area[1]),
            ));
            let from = goals.last().map_or(from, |g| (g.x, g.y));
            goals.extend(motion::wander_goals(
                from,
                *area,
                *speed,
                *pause_s,
                leave - p.enter_s + 10.0,
                &world.obstacles,
                &mut r,
            ));
            let first = start.unwrap_or((from.0, from.1, 0.0));
            Ok(motion::walk(first, &goals, p.enter_s, leave, &mut r))
        }
        Motion::Replay {
            file,
            track,
            offset,
            rotate_deg,
        } => {
            let path = if Path::new(file).is_absolute() {
                PathBuf::from(file)
            } else {
                base.join(file)
            };
            motion::replay(&path, *track, *offset, rotate_deg.to_radians(), p.enter_s)
                .map_err(SynthError::Scenario)
        }
    }
}

/// Build every actor of a session (scripted people, then the crowd).
fn actors(
    s: &Scenario,
    world: &World,
    base: &Path,
    session: u64,
    robot: Option<&RobotTrack>,
) -> Result<Vec<Actor>, SynthError> {
    let mut out = Vec::new();
    for p in &s.people {
        out.push(Actor {
            body: Body::from_spec(p),
            track: scripted_track(s, p, world, base, session)?,
        });
    }
    if let Some(c) = &s.crowd {
        let mut r = rng::stream(s.scenario.seed, "crowd", session);
        let dur = s.scenario.duration_s;
        let first_id = s.people.iter().map(|p| p.id).max().unwrap_or(0) + 1;
        for (k, next_id) in (0..c.count).zip(first_id..) {
            let height = c.height[0] + r.random::<f64>() * (c.height[1] - c.height[0]);
            let body = Body {
                id: next_id,
                height,
                width: 0.17 + 0.06 * r.random::<f64>(),
                leg_radius: 0.055 + 0.02 * r.random::<f64>(),
                upper: random_color(&mut r),
                lower: random_color(&mut r),
                skin: skin_tone(&mut r),
                hair: [
                    50 + r.random_range(0..60u8),
                    35 + r.random_range(0..40u8),
                    25,
                ],
                hat: None,
            };
            let stay = c.stay_s[0] + r.random::<f64>() * (c.stay_s[1] - c.stay_s[0]);
            // spread arrivals over the session
            let enter = (dur - stay.min(dur)).max(0.0) * (k as f64 + r.random::<f64>())
                / f64::from(c.count.max(1));
            let leave = (enter + stay).min(dur);
            let speed = || c.speed[0];
            let track = if let (Some(_), Some(robot)) = (c.cross_between_robot_and, robot) {
                // cross the robot–target line at a random time
                let target = out
                    .iter()
                    .find(|a| Some(a.body.id) == c.cross_between_robot_and)
                    .map(|a| &a.track)
                    .ok_or_else(|| {
                        SynthError::Scenario("crowd.cross_between_robot_and names no person".into())
                    })?;
                let tc = enter + stay / 2.0;
                let rs = robot.state(tc);
                let tp = target.position(tc).unwrap_or((rs.x + 2.0, rs.y));
                let (mx, my) = ((rs.x + tp.0) / 2.0, (rs.y + tp.1) / 2.0);
                let (dx, dy) = (tp.0 - rs.x, tp.1 - rs.y);
                let len = dx.hypot(dy).max(1e-6);
                let (nx, ny) = (-dy / len, dx / len);
                let v = c.speed[0] + r.random::<f64>() * (c.speed[1] - c.speed[0]);
                let side = if r.random::<bool>() { 1.0 } else { -1.0 };
                let half = 0.5 * stay * v;
                let a = (mx - side * nx * half, my - side * ny * half);
                let b = (mx + side * nx * half, my + side * ny * half);
                motion::walk(
                    (a.0, a.1, (b.1 - a.1).atan2(b.0 - a.0)),
                    &[Goal {
                        x: b.0,
                        y: b.1,
                        speed: v,
                        pause: 0.0,
                    }],
                    enter,
                    leave,
                    &mut r,
                )
            } else {
                let doors = &world.doors;
                let (from, to) = if c.use_doors && !doors.is_empty() {
                    // step 0.4 m into the room from the door in the wall
                    let inside = |d: [f64; 2]| {
                        let (cx, cy) = (world.size[0] / 2.0, world.size[1] / 2.0);
                        let (dx, dy) = (cx - d[0], cy - d[1]);
                        let n = dx.hypot(dy).max(1e-9);
                        (d[0] + 0.4 * dx / n, d[1] + 0.4 * dy / n)
                    };
                    let a = inside(doors[r.random_range(0..doors.len())]);
                    let b = inside(doors[r.random_range(0..doors.len())]);
                    (a, Some(b))
                } else {
                    let area = c.area;
                    (
                        (
                            area[0] + r.random::<f64>() * (area[2] - area[0]),
                            area[1] + r.random::<f64>() * (area[3] - area[1]),
                        ),
                        None,
                    )
                };
                let mut goals = motion::wander_goals(
                    from,
                    c.area,
                    [speed(), c.speed[1]],
                    [0.0, 3.0],
                    stay * 0.8,
                    &world.obstacles,
                    &mut r,
                );
                if let Some(to) = to {
                    goals.push(Goal {
                        x: to.0,
                        y: to.1,
                        speed: c.speed[1],
                        pause: 0.0,
                    });
                }
                motion::walk((from.0, from.1, 0.0), &goals, enter, leave, &mut r)
            };
            out.push(Actor { body, track });
        }
    }
    Ok(out)
}

/// `(mount pose, on_robot)` of a sensor; applies the perturbation of fixed cameras.
fn mount_pose(
    m: &super::scenario::Mount,
    optical: bool,
    r: &mut rand_chacha::ChaCha8Rng,
) -> (Isometry3<f64>, Isometry3<f64>) {
    let nominal = match (m.look_at, optical) {
        (Some(target), true) => geometry::look_at(Point3::from(m.xyz), Point3::from(target)),
        _ => {
            let body = geometry::pose_xyz_rpy(
                m.xyz,
                [
                    m.rpy_deg[0].to_radians(),
                    m.rpy_deg[1].to_radians(),
                    m.rpy_deg[2].to_radians(),
                ],
            );
            if optical {
                body * Isometry3::from_parts(
                    Translation3::identity(),
                    geometry::body_from_optical(),
                )
            } else {
                body
            }
        }
    };
    let actual = match m.perturb {
        Some([dp, dyaw]) if m.on == MountFrame::World => {
            let a = r.random::<f64>() * std::f64::consts::TAU;
            let d = dp * r.random::<f64>().sqrt();
            let yaw = (r.random::<f64>() * 2.0 - 1.0) * dyaw.to_radians();
            let t = nominal.translation.vector + Vector3::new(d * a.cos(), d * a.sin(), 0.0);
            Isometry3::from_parts(
                Translation3::from(t),
                UnitQuaternion::from_euler_angles(0.0, 0.0, yaw) * nominal.rotation,
            )
        }
        _ => nominal,
    };
    (nominal, actual)
}

fn quat(q: &UnitQuaternion<f64>) -> Quaternion<f64> {
    *q.quaternion()
}

fn tf(parent: &str, child: &str, stamp: Nanos, pose: &Isometry3<f64>) -> TransformStamped {
    TransformStamped {
        header: Header::new(stamp, parent),
        child_frame_id: child.to_string(),
        transform: Transform {
            translation: pose.translation.vector,
            rotation: quat(&pose.rotation),
        },
    }
}

#[derive(Serialize)]
struct CameraTruth {
    name: String,
    nominal_xyz: [f64; 3],
    nominal_yaw_deg: f64,
    true_xyz: [f64; 3],
    true_yaw_deg: f64,
    model: String,
}

/// Heading of a pose's viewing direction projected on the floor (deg): optical z for pinholes.
fn heading_deg(p: &Isometry3<f64>, optical: bool) -> f64 {
    let fwd = if optical {
        p.rotation * Vector3::z()
    } else {
        p.rotation * Vector3::x()
    };
    fwd.y.atan2(fwd.x).to_degrees()
}

/// Simulate session `index` of a scenario and write it to `path`. Returns what the preview needs.
#[allow(clippy::too_many_lines)]
pub fn write_session(
    s: &Scenario,
    scenario_text: &str,
    profile: &str,
    base: &Path,
    index: u32,
    path: &Path,
    bar: &dyn Progress,
) -> Result<PreviewData, SynthError> {
    let seed = rng::hash(s.scenario.seed, &[u64::from(index)]);
    let session = u64::from(index);
    let dur = s.scenario.duration_s;
    let world = World::build(s, session);
    let t0 = Nanos((EPOCH_S + 10_000 * session) * Nanos::NANOS_PER_SEC);
    let at = |t: f64| Nanos(t0.0 + (t * 1e9).round() as u64);

    // people first (the robot may follow one), then the robot, then people who cross its path
    let mut people = actors(
        &Scenario {
            crowd: None,
            ..s.clone()
        },
        &world,
        base,
        session,
        None,
    )?;
    let target_track = s
        .robot
        .follow
        .as_ref()
        .and_then(|f| people.iter().find(|a| a.body.id == f.target))
        .map(|a| &a.track);
    let robot_track = robot::simulate(&s.robot, dur, target_track, s.scenario.seed, session);
    if s.crowd.is_some() {
        let crowd_only = Scenario {
            people: Vec::new(),
            ..s.clone()
        };
        let mut crowd = if s
            .crowd
            .as_ref()
            .is_some_and(|c| c.cross_between_robot_and.is_some())
        {
            // crossers need the target's track: build with the scripted people present
            let all = actors(s, &world, base, session, Some(&robot_track))?;
            all.into_iter().skip(s.people.len()).collect()
        } else {
            actors(&crowd_only, &world, base, session, Some(&robot_track))?
        };
        people.append(&mut crowd);
    }

    let mut w = SessionWriter::create(path, &WriterOptions::default())?;
    let mut meta = BTreeMap::new();
    meta.insert("scenario".to_string(), s.scenario.name.clone());
    meta.insert("seed".to_string(), s.scenario.seed.to_string());
    meta.insert("session_seed".to_string(), seed.to_string());
    meta.insert("session".to_string(), index.to_string());
    meta.insert("profile".to_string(), profile.to_string());
    meta.insert("generator".to_string(), GENERATOR_VERSION.to_string());
    meta.insert("paper".to_string(), s.scenario.paper.clone());
    meta.insert("scenario_toml".to_string(), scenario_text.to_string());
    w.metadata("peopletrack.scenario", meta)?;

    // sensors
    let mut sensors = Vec::new();
    let mut statics = Vec::new();
    let mut truth_cams = Vec::new();
    let mut mount_rng = rng::stream(s.scenario.seed, "mounts", 0); // the same perturbation in every session
    let laser_height = s
        .sensors
        .iter()
        .find_map(|x| {
            if let SensorSpec::Laser { mount, .. } = x {
                Some(mount.xyz[2])
            } else {
                None
            }
        })
        .unwrap_or(0.25);
    for (k, spec) in s.sensors.iter().enumerate() {
        match spec {
            SensorSpec::Laser {
                name,
                mount,
                rate_hz,
                fov_deg,
                resolution_deg,
                range_min,
                range_max,
                noise_m,
                dropout,
                topic,
            } => {
                let (_, pose) = mount_pose(mount, false, &mut mount_rng);
                let on_robot = mount.on == MountFrame::Robot;
                statics.push(tf(
                    if on_robot { "base_link" } else { "map" },
                    name,
                    at(0.0),
                    &pose,
                ));
                sensors.push(SensorRuntime::Laser {
                    spec: LaserSpec {
                        fov: fov_deg.to_radians(),
                        increment: resolution_deg.to_radians(),
                        range_min: *range_min,
                        range_max: *range_max,
                        noise_m: *noise_m,
                        dropout: *dropout,
                    },
                    frame_id: name.clone(),
                    mount: pose,
                    on_robot,
                    rate: *rate_hz,
                    channel: w.add_ros2::<LaserScan>(topic)?,
                });
            }
            SensorSpec::Pinhole { camera, .. }
            | SensorSpec::Paracatadioptric { camera, .. }
            | SensorSpec::Conical { camera, .. } => {
                let (model, optical) = match spec {
                    SensorSpec::Pinhole {
                        hfov_deg,
                        distortion,
                        ..
                    } => (
                        CameraModel::Pinhole(Pinhole {
                            dist: *distortion,
                            ..Pinhole::from_fov(camera.width, camera.height, *hfov_deg)
                        }),
                        true,
                    ),
                    SensorSpec::Paracatadioptric {
                        f, r_min, r_max, ..
                    } => (
                        CameraModel::Paracatadioptric(Paracatadioptric {
                            width: camera.width,
                            height: camera.height,
                            xc: f64::from(camera.width) / 2.0,
                            yc: f64::from(camera.height) / 2.0,
                            f: *f,
                            r_min: *r_min,
                            r_max: *r_max,
                        }),
                        false,
                    ),
                    SensorSpec::Conical {
                        f,
                        apex_m,
                        alpha_deg,
                        top_m,
                        ..
                    } => (
                        CameraModel::ConicalMirror(ConicalMirror {
                            width: camera.width,
                            height: camera.height,
                            xc: f64::from(camera.width) / 2.0,
                            yc: f64::from(camera.height) / 2.0,
                            f: *f,
                            d: *apex_m,
                            alpha: alpha_deg.to_radians(),
                            z_top: *top_m,
                        }),
                        false,
                    ),
                    SensorSpec::Laser { .. } => unreachable!("handled above"),
                };
                let (nominal, pose) = mount_pose(&camera.mount, optical, &mut mount_rng);
                let on_robot = camera.mount.on == MountFrame::Robot;
                let fixed = (!on_robot || s.robot.mode == RobotMode::Static).then(|| {
                    let world_pose = if on_robot {
                        robot_track.state(0.0).pose() * pose
                    } else {
                        pose
                    };
                    (world_pose, &world)
                });
                let cam = Camera::new(&camera.name, model.clone(), camera.noise, fixed, k as u64);
                // TF carries what the installer believes (the nominal pose); a perturbed camera
                // renders from its true pose, recorded only in the `peopletrack.truth` metadata
                statics.push(tf(
                    if on_robot { "base_link" } else { "map" },
                    &camera.name,
                    at(0.0),
                    &nominal,
                ));
                truth_cams.push(CameraTruth {
                    name: camera.name.clone(),
                    nominal_xyz: nominal.translation.vector.into(),
                    nominal_yaw_deg: heading_deg(&nominal, optical),
                    true_xyz: pose.translation.vector.into(),
                    true_yaw_deg: heading_deg(&pose, optical),
                    model: CameraInfo::from_model(&model, Header::default()).distortion_model,
                });
                let image_ch = match camera.format {
                    ImageFormat::Raw => {
                        w.add_ros2::<Image>(&format!("/{}/image_raw", camera.name))?
                    }
                    ImageFormat::Jpeg => w.add_ros2::<CompressedImage>(&format!(
                        "/{}/image_raw/compressed",
                        camera.name
                    ))?,
                };
                let info_ch = w.add_ros2::<CameraInfo>(&format!("/{}/camera_info", camera.name))?;
                let mask_ch = if camera.mask {
                    Some(w.add_ros2::<Image>(&format!("/{}/ground_truth_mask", camera.name))?)
                } else {
                    None
                };
                sensors.push(SensorRuntime::Camera {
                    cam: Box::new(cam),
                    frame_id: camera.name.clone(),
                    mount: pose,
                    on_robot,
                    rate: camera.rate_hz,
                    format: camera.format,
                    quality: camera.jpeg_quality,
                    mask: camera.mask,
                    channels: (image_ch, info_ch, mask_ch),
                });
            }
        }
    }
    let mut truth = BTreeMap::new();
    truth.insert(
        "cameras".to_string(),
        serde_json::to_string(&truth_cams).unwrap_or_default(),
    );
    w.metadata("peopletrack.truth", truth)?;

    let tf_static_ch = w.add_ros2::<TfMessage>("/tf_static")?;
    let tf_ch = w.add_ros2::<TfMessage>("/tf")?;
    let odom_ch = w.add_ros2::<Odometry>("/odom")?;
    let imu_ch = w.add_ros2::<Imu>("/imu")?;
    let gt_ch = w.add_json(
        groundtruth::PEOPLE_TOPIC,
        groundtruth::PEOPLE_SCHEMA,
        groundtruth::PEOPLE_JSON_SCHEMA,
    )?;
    let calib_ch = match &s.calibration {
        Some(_) => Some(w.add_json(
            groundtruth::TARGETS_TOPIC,
            groundtruth::TARGETS_SCHEMA,
            groundtruth::TARGETS_JSON_SCHEMA,
        )?),
        None => None,
    };
    w.write(
        tf_static_ch,
        at(0.0),
        &TfMessage {
            transforms: statics,
        },
    )?;

    // odometry and IMU
    let odo = robot::odometry(
        &robot_track,
        s.robot.odom_noise,
        s.robot.odom_rate_hz,
        dur,
        s.scenario.seed,
        session,
    );
    for (t, [x, y, yaw], v, wz) in &odo {
        let stamp = at(*t);
        let log = Nanos(stamp.0 + 1_000_000);
        let odom_from_base = Isometry3::from_parts(
            Translation3::new(*x, *y, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, *yaw),
        );
        let truth = robot_track.state(*t).pose();
        // perfect localisation: map -> odom makes map -> base_link equal the true pose
        let map_from_odom = truth * odom_from_base.inverse();
        w.write(
            odom_ch,
            log,
            &Odometry {
                header: Header::new(stamp, "odom"),
                child_frame_id: "base_link".into(),
                pose: Pose {
                    position: Point3::new(*x, *y, 0.0),
                    orientation: quat(&odom_from_base.rotation),
                },
                pose_covariance: [0.0; 36],
                linear: Vector3::new(*v, 0.0, 0.0),
                angular: Vector3::new(0.0, 0.0, *wz),
                twist_covariance: [0.0; 36],
            },
        )?;
        w.write(
            tf_ch,
            log,
            &TfMessage {
                transforms: vec![
                    tf("odom", "base_link", stamp, &odom_from_base),
                    tf("map", "odom", stamp, &map_from_odom),
                ],
            },
        )?;
    }
    let imu_dt = 1.0 / s.robot.imu_rate_hz;
    let mut imu_rng = rng::stream(s.scenario.seed, "imu", session);
    let mut k = 0u64;
    loop {
        let t = k as f64 * imu_dt;
        if t >= dur {
            break;
        }
        let st = robot_track.state(t);
        let q = UnitQuaternion::from_euler_angles(0.0, st.pitch, st.yaw);
        let a_world = Vector3::new(st.accel * st.yaw.cos(), st.accel * st.yaw.sin(), 9.81);
        let f = q.inverse() * a_world;
        let n = |r: &mut rand_chacha::ChaCha8Rng, s: f64| s * (r.random::<f64>() - 0.5) * 3.46;
        let stamp = at(t);
        w.write(
            imu_ch,
            Nanos(stamp.0 + 500_000),
            &Imu {
                header: Header::new(stamp, "base_link"),
                orientation: quat(&q),
                orientation_covariance: [0.0; 9],
                angular_velocity: Vector3::new(
                    n(&mut imu_rng, 0.002),
                    st.pitch_rate + n(&mut imu_rng, 0.002),
                    st.w + n(&mut imu_rng, 0.002),
                ),
                angular_velocity_covariance: [0.0; 9],
                linear_acceleration: f + Vector3::new(
                    n(&mut imu_rng, 0.02),
                    n(&mut imu_rng, 0.02),
                    n(&mut imu_rng, 0.02),
                ),
                linear_acceleration_covariance: [0.0; 9],
            },
        )?;
        k += 1;
    }

    // sensor schedule: (time, sensor index, frame number)
    let mut events: Vec<(u64, usize, u64)> = Vec::new();
    for (i, sen) in sensors.iter().enumerate() {
        let period = 1.0 / sen.rate();
        // cameras are triggered together (as multi-camera rigs are); lasers free-run with a
        // small offset
        let phase = match sen {
            SensorRuntime::Camera { .. } => 0.0,
            SensorRuntime::Laser { .. } => {
                f64::from(rng::unit(rng::hash(seed, &[0x9a5e, i as u64]))) * period.min(0.02)
            }
        };
        let mut n = 0u64;
        loop {
            let t = phase + n as f64 * period;
            if t >= dur {
                break;
            }
            events.push(((t * 1e9).round() as u64, i, n));
            n += 1;
        }
    }
    events.sort();
    bar.set_length(events.len() as u64);
    let mid = events.get(events.len() / 2).map_or(0, |e| e.0);
    let mut previewed: Vec<bool> = vec![false; sensors.len()];
    let mut preview = PreviewData {
        t: 0.0,
        cameras: Vec::new(),
        scan_points: Vec::new(),
        people: Vec::new(),
        robot: [0.0; 3],
        sensors: Vec::new(),
        world: world.clone(),
    };
    let mut dynamic: Vec<Primitive> = Vec::new();
    let mut e = 0;
    while e < events.len() {
        let t_ns = events[e].0;
        let group_end = events[e..]
            .iter()
            .position(|x| x.0 != t_ns)
            .map_or(events.len(), |p| e + p);
        let t = t_ns as f64 * 1e-9;
        let stamp = at(t);
        let rs = robot_track.state(t);
        let base = rs.pose();
        let states: Vec<(usize, PersonState)> = people
            .iter()
            .enumerate()
            .filter_map(|(i, a)| a.track.state(t).map(|st| (i, st)))
            .collect();
        dynamic.clear();
        world.moving_at(t, &mut dynamic);
        let mut per_person: Vec<Vec<Primitive>> = Vec::new();
        for (i, st) in &states {
            let mut prims = Vec::new();
            people[*i].body.primitives(st, &mut prims);
            dynamic.extend(prims.iter().cloned());
            per_person.push(prims);
        }
        let shadows: Vec<[f64; 3]> = states
            .iter()
            .map(|(i, st)| [st.x, st.y, people[*i].body.shadow_radius()])
            .collect();
        // views[slot]: what each camera that captured this instant saw of person `states[slot]`
        let mut views: Vec<Vec<CameraView>> = vec![Vec::new(); states.len()];
        let is_mid = t_ns == mid;
        for &(_, si, n) in &events[e..group_end] {
            match &sensors[si] {
                SensorRuntime::Camera {
                    cam,
                    frame_id,
                    mount,
                    on_robot,
                    format,
                    quality,
                    mask,
                    channels,
                    ..
                } => {
                    let pose = if *on_robot { base * mount } else { *mount };
                    let frame = cam.render(&FrameInput {
                        world: &world,
                        dynamic: &dynamic,
                        shadows: &shadows,
                        t,
                        pose,
                        noise_key: rng::hash(seed, &[n, si as u64]),
                    });
                    let (wdt, hgt) = (frame.width, frame.height);
                    let log = Nanos(stamp.0 + latency(seed, si, n, 8.0, 25.0));
                    let header = Header::new(stamp, frame_id.clone());
                    match format {
                        ImageFormat::Raw => w.write(
                            channels.0,
                            log,
                            &Image {
                                header: header.clone(),
                                height: hgt,
                                width: wdt,
                                encoding: "rgb8".into(),
                                is_bigendian: 0,
                                step: wdt * 3,
                                data: frame.rgb.clone(),
                            },
                        )?,
                        ImageFormat::Jpeg => {
                            let mut buf = Vec::new();
                            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut buf, *quality)
                                .encode(&frame.rgb, wdt, hgt, image::ExtendedColorType::Rgb8)
                                .map_err(|e| SynthError::Encode {
                                    camera: frame_id.clone(),
                                    reason: e.to_string(),
                                })?;
                            w.write(
                                channels.0,
                                log,
                                &CompressedImage {
                                    header: header.clone(),
                                    format: "jpeg".into(),
                                    data: buf,
                                },
                            )?;
                        }
                    }
                    w.write(
                        channels.1,
                        log,
                        &CameraInfo::from_model(&cam.model, header.clone()),
                    )?;
                    if *mask && let Some(ch) = channels.2 {
                        let data: Vec<u8> = frame
                            .ids
                            .iter()
                            .map(|id| if *id >= PERSON_BASE { 255 } else { 0 })
                            .collect();
                        w.write(
                            ch,
                            log,
                            &Image {
                                header,
                                height: hgt,
                                width: wdt,
                                encoding: "mono8".into(),
                                is_bigendian: 0,
                                step: wdt,
                                data,
                            },
                        )?;
                    }
                    // ground-truth views of this camera
                    let cam_from_world = pose.inverse();
                    let mut seen_here = Vec::new();
                    for (slot, ((i, st), prims)) in states.iter().zip(&per_person).enumerate() {
                        let id = people[*i].body.object();
                        let (mut x0, mut y0, mut x1, mut y1, mut count) =
                            (u32::MAX, u32::MAX, 0u32, 0u32, 0u64);
                        for (p, pid) in frame.ids.iter().enumerate() {
                            if *pid == id {
                                let (x, y) = ((p % wdt as usize) as u32, (p / wdt as usize) as u32);
                                x0 = x0.min(x);
                                y0 = y0.min(y);
                                x1 = x1.max(x);
                                y1 = y1.max(y);
                                count += 1;
                            }
                        }
                        let full = cam.unoccluded_pixels(&pose, prims);
                        if full == 0 {
                            continue;
                        }
                        let head = cam
                            .model
                            .project(&(cam_from_world * people[*i].body.head_top(st)))
                            .filter(|p| cam.model.in_image(p));
                        let view = CameraView {
                            camera: frame_id.clone(),
                            bbox: (count > 0).then(|| {
                                [
                                    f64::from(x0),
                                    f64::from(y0),
                                    f64::from(x1) + 1.0,
                                    f64::from(y1) + 1.0,
                                ]
                            }),
                            head_px: head.map(|p| [p.x, p.y]),
                            visibility: (count as f64 / full as f64).min(1.0),
                        };
                        seen_here.push((people[*i].body.id, view.clone()));
                        views[slot].push(view);
                    }
                    if t_ns >= mid && !previewed[si] {
                        previewed[si] = true;
                        let img =
                            RgbImage::from_raw(wdt, hgt, frame.rgb.clone()).ok_or_else(|| {
                                SynthError::Encode {
                                    camera: frame_id.clone(),
                                    reason: "frame size".into(),
                                }
                            })?;
                        preview.cameras.push((frame_id.clone(), img, seen_here));
                        preview
                            .sensors
                            .push((frame_id.clone(), pose.translation.vector.into()));
                    }
                }
                SensorRuntime::Laser {
                    spec,
                    frame_id,
                    mount,
                    on_robot,
                    channel,
                    ..
                } => {
                    let pose = if *on_robot { base * mount } else { *mount };
                    let (ranges, _) = scan(
                        spec,
                        &pose,
                        &[&world.statics, &dynamic],
                        rng::hash(seed, &[n, si as u64, 0x1a5e]),
                    );
                    if t_ns >= mid && !previewed[si] {
                        previewed[si] = true;
                        preview.scan_points = ranges
                            .iter()
                            .enumerate()
                            .filter(|(_, r)| r.is_finite())
                            .map(|(b, r)| {
                                let a = spec.angle_min() + b as f64 * spec.increment;
                                let p = pose
                                    * Point3::new(
                                        f64::from(*r) * a.cos(),
                                        f64::from(*r) * a.sin(),
                                        0.0,
                                    );
                                [p.x, p.y]
                            })
                            .collect();
                        preview
                            .sensors
                            .push((frame_id.clone(), pose.translation.vector.into()));
                    }
                    let log = Nanos(stamp.0 + latency(seed, si, n, 3.0, 8.0));
                    w.write(
                        *channel,
                        log,
                        &LaserScan {
                            header: Header::new(stamp, frame_id.clone()),
                            angle_min: spec.angle_min() as f32,
                            angle_max: (spec.angle_min()
                                + (spec.beams() - 1) as f64 * spec.increment)
                                as f32,
                            angle_increment: spec.increment as f32,
                            time_increment: 0.0,
                            scan_time: (1.0 / sensors[si].rate()) as f32,
                            range_min: spec.range_min as f32,
                            range_max: spec.range_max as f32,
                            ranges,
                            intensities: Vec::new(),
                        },
                    )?;
                }
            }
            bar.inc(1);
        }
        // ground truth at this instant, with the views of the cameras that captured it
        let gt_people: Vec<PersonTruth> = states
            .iter()
            .zip(views)
            .map(|((i, st), cameras)| {
                let b = &people[*i].body;
                PersonTruth {
                    id: b.id,
                    x: st.x,
                    y: st.y,
                    vx: st.vx,
                    vy: st.vy,
                    height: b.height,
                    head_z: b.head_center(st).z,
                    radius: b.width,
                    legs: b.legs_at(st, laser_height),
                    leg_radius: b.leg_radius,
                    cameras,
                }
            })
            .collect();
        if is_mid {
            preview.t = t;
            preview.people = gt_people.clone();
            preview.robot = [rs.x, rs.y, rs.yaw];
        }
        w.write_json(
            gt_ch,
            stamp,
            &PeopleFrame {
                stamp_ns: stamp.0,
                people: gt_people,
            },
        )?;
        if let (Some(ch), Some(c)) = (calib_ch, &s.calibration)
            && let Some((i, st)) = states.iter().find(|(i, _)| people[*i].body.id == c.person)
            && st.speed < 0.02
            && let Some(k) = c
                .positions
                .iter()
                .position(|p| (p[0] - st.x).hypot(p[1] - st.y) < CALIBRATION_MARK_RADIUS)
        {
            let b = &people[*i].body;
            let hat = b.hat_center(st).unwrap_or_else(|| b.head_top(st));
            w.write_json(
                ch,
                stamp,
                &TargetsFrame {
                    stamp_ns: stamp.0,
                    targets: vec![Target {
                        id: k as u32,
                        x: hat.x,
                        y: hat.y,
                        z: hat.z,
                    }],
                },
            )?;
        }
        e = group_end;
    }
    w.finish()?;
    Ok(preview)
}
