//! A session's sensors as installed: every sensor's mount (with the perturbation of fixed
//! cameras), its runtime state and channels, the static transforms, what the cameras' true
//! poses are (the `peopletrack.truth` metadata), and the channels every session has.

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rand::RngExt;
use serde::Serialize;

use super::types::{Clock, SynthError};
use crate::geometry;
use crate::geometry::camera::{CameraModel, ConicalMirror, Paracatadioptric, Pinhole};
use crate::groundtruth;
use crate::log::msgs::{
    CameraInfo, CompressedImage, Header, Image, Imu, LaserScan, Odometry, TfMessage, Transform,
    TransformStamped,
};
use crate::log::{ChannelId, SessionWriter};
use crate::rng;
use crate::synth::laser::LaserSpec;
use crate::synth::render::Camera;
use crate::synth::robot::RobotTrack;
use crate::synth::scenario::{
    CameraCommon, ImageFormat, Mount, MountFrame, RobotMode, Scenario, SensorSpec,
};
use crate::synth::world::World;
use crate::time::Nanos;

/// A camera as the session runs it.
pub(super) struct CameraSensor {
    pub cam: Box<Camera>,
    pub frame_id: String,
    /// `base_from_sensor` for robot-mounted, `map_from_sensor` for fixed.
    pub mount: Isometry3<f64>,
    pub on_robot: bool,
    pub rate: f64,
    pub format: ImageFormat,
    pub quality: u8,
    pub mask: bool,
    /// Image, camera info and (when recorded) ground-truth mask.
    pub channels: (ChannelId, ChannelId, Option<ChannelId>),
    /// Ground-truth skin mask channel, when the camera records one (`skin_mask = true`).
    pub skin_channel: Option<ChannelId>,
    /// Per-person id mask channel, when the camera records one (`id_mask = true`).
    pub id_channel: Option<ChannelId>,
}

/// A laser scanner as the session runs it.
pub(super) struct LaserSensor {
    pub spec: LaserSpec,
    pub frame_id: String,
    pub mount: Isometry3<f64>,
    pub on_robot: bool,
    pub rate: f64,
    pub channel: ChannelId,
}

pub(super) enum SensorRuntime {
    Camera(CameraSensor),
    Laser(LaserSensor),
}

impl SensorRuntime {
    pub fn rate(&self) -> f64 {
        match self {
            SensorRuntime::Camera(c) => c.rate,
            SensorRuntime::Laser(l) => l.rate,
        }
    }
}

/// The sensors of a session, in the scenario's order, with the static transforms of their
/// mounts (not yet written).
pub(super) struct Rig {
    pub sensors: Vec<SensorRuntime>,
    pub statics: Vec<TransformStamped>,
    /// Height of the first laser (m), where the ground truth measures legs; 0.25 without one.
    pub laser_height: f64,
}

/// The channels every session has besides its sensors'.
pub(super) struct Channels {
    pub tf_static: ChannelId,
    pub tf: ChannelId,
    pub odom: ChannelId,
    pub imu: ChannelId,
    pub people: ChannelId,
    /// Calibration targets, when the scenario has a calibration walk.
    pub targets: Option<ChannelId>,
    /// The follower's state, when the robot follows in a closed loop (added last).
    pub follower: Option<ChannelId>,
}

/// Install every sensor of `s`: add its channels to `w`, then write the cameras' true poses
/// as the `peopletrack.truth` metadata.
pub(super) fn install(
    w: &mut SessionWriter,
    s: &Scenario,
    world: &World,
    robot_track: &RobotTrack,
    clock: Clock,
) -> Result<Rig, SynthError> {
    let mut b = Builder {
        s,
        world,
        robot_track,
        clock,
        // the same perturbation in every session
        mount_rng: rng::stream(s.scenario.seed, "mounts", 0),
        sensors: Vec::new(),
        statics: Vec::new(),
        truth_cams: Vec::new(),
    };
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
            SensorSpec::Laser { .. } => b.add_laser(w, spec)?,
            SensorSpec::Pinhole { .. }
            | SensorSpec::Paracatadioptric { .. }
            | SensorSpec::Conical { .. } => b.add_camera(w, k, spec)?,
        }
    }
    let mut truth = BTreeMap::new();
    truth.insert(
        "cameras".to_string(),
        serde_json::to_string(&b.truth_cams).unwrap_or_default(),
    );
    w.metadata("peopletrack.truth", truth)?;
    Ok(Rig {
        sensors: b.sensors,
        statics: b.statics,
        laser_height,
    })
}

impl Channels {
    /// Add the TF, odometry, IMU and ground-truth channels, in this order.
    pub fn add(w: &mut SessionWriter, s: &Scenario) -> Result<Channels, SynthError> {
        let tf_static = w.add_ros2::<TfMessage>("/tf_static")?;
        let tf = w.add_ros2::<TfMessage>("/tf")?;
        let odom = w.add_ros2::<Odometry>("/odom")?;
        let imu = w.add_ros2::<Imu>("/imu")?;
        let people = w.add_json(
            groundtruth::PEOPLE_TOPIC,
            groundtruth::PEOPLE_SCHEMA,
            groundtruth::PEOPLE_JSON_SCHEMA,
        )?;
        let targets = match &s.calibration {
            Some(_) => Some(w.add_json(
                groundtruth::TARGETS_TOPIC,
                groundtruth::TARGETS_SCHEMA,
                groundtruth::TARGETS_JSON_SCHEMA,
            )?),
            None => None,
        };
        let closed_loop = s.robot.mode == RobotMode::Follow
            && s.robot.follow.as_ref().is_some_and(|f| f.closed_loop);
        let follower = if closed_loop {
            Some(w.add_json(
                groundtruth::FOLLOWER_TOPIC,
                groundtruth::FOLLOWER_SCHEMA,
                groundtruth::FOLLOWER_JSON_SCHEMA,
            )?)
        } else {
            None
        };
        Ok(Channels {
            tf_static,
            tf,
            odom,
            imu,
            people,
            targets,
            follower,
        })
    }
}

struct Builder<'a> {
    s: &'a Scenario,
    world: &'a World,
    robot_track: &'a RobotTrack,
    clock: Clock,
    mount_rng: rand_chacha::ChaCha8Rng,
    sensors: Vec<SensorRuntime>,
    statics: Vec<TransformStamped>,
    truth_cams: Vec<CameraTruth>,
}

impl Builder<'_> {
    fn add_laser(&mut self, w: &mut SessionWriter, spec: &SensorSpec) -> Result<(), SynthError> {
        let SensorSpec::Laser {
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
        } = spec
        else {
            return Ok(());
        };
        let (_, pose) = mount_pose(mount, false, &mut self.mount_rng);
        let on_robot = mount.on == MountFrame::Robot;
        self.statics.push(tf(
            if on_robot { "base_link" } else { "map" },
            name,
            self.clock.at(0.0),
            &pose,
        ));
        self.sensors.push(SensorRuntime::Laser(LaserSensor {
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
        }));
        Ok(())
    }

    fn add_camera(
        &mut self,
        w: &mut SessionWriter,
        k: usize,
        spec: &SensorSpec,
    ) -> Result<(), SynthError> {
        let (SensorSpec::Pinhole { camera, .. }
        | SensorSpec::Paracatadioptric { camera, .. }
        | SensorSpec::Conical { camera, .. }) = spec
        else {
            return Ok(());
        };
        let (model, optical) = camera_model(spec, camera);
        let (nominal, pose) = mount_pose(&camera.mount, optical, &mut self.mount_rng);
        let on_robot = camera.mount.on == MountFrame::Robot;
        let fixed = (!on_robot || self.s.robot.mode == RobotMode::Static).then(|| {
            let world_pose = if on_robot {
                self.robot_track.state(0.0).pose() * pose
            } else {
                pose
            };
            (world_pose, self.world)
        });
        let cam = Camera::new(&camera.name, model.clone(), camera.noise, fixed, k as u64);
        // TF carries what the installer believes (the nominal pose); a perturbed camera
        // renders from its true pose, recorded only in the `peopletrack.truth` metadata
        self.statics.push(tf(
            if on_robot { "base_link" } else { "map" },
            &camera.name,
            self.clock.at(0.0),
            &nominal,
        ));
        self.truth_cams.push(CameraTruth {
            name: camera.name.clone(),
            nominal_xyz: nominal.translation.vector.into(),
            nominal_yaw_deg: heading_deg(&nominal, optical),
            true_xyz: pose.translation.vector.into(),
            true_yaw_deg: heading_deg(&pose, optical),
            model: CameraInfo::from_model(&model, Header::default()).distortion_model,
        });
        let image_ch = match camera.format {
            ImageFormat::Raw => w.add_ros2::<Image>(&format!("/{}/image_raw", camera.name))?,
            ImageFormat::Jpeg => {
                w.add_ros2::<CompressedImage>(&format!("/{}/image_raw/compressed", camera.name))?
            }
        };
        let info_ch = w.add_ros2::<CameraInfo>(&format!("/{}/camera_info", camera.name))?;
        let mask_ch = if camera.mask {
            Some(w.add_ros2::<Image>(&format!("/{}/ground_truth_mask", camera.name))?)
        } else {
            None
        };
        let skin_channel = if camera.skin_mask {
            Some(w.add_ros2::<Image>(&format!("/{}/ground_truth_skin", camera.name))?)
        } else {
            None
        };
        let id_channel = if camera.id_mask {
            Some(w.add_ros2::<Image>(&format!("/{}/ground_truth_ids", camera.name))?)
        } else {
            None
        };
        self.sensors.push(SensorRuntime::Camera(CameraSensor {
            cam: Box::new(cam),
            frame_id: camera.name.clone(),
            mount: pose,
            on_robot,
            rate: camera.rate_hz,
            format: camera.format,
            quality: camera.jpeg_quality,
            mask: camera.mask,
            channels: (image_ch, info_ch, mask_ch),
            skin_channel,
            id_channel,
        }));
        Ok(())
    }
}

/// The camera model of a camera sensor, and whether its frame is optical (z forward).
fn camera_model(spec: &SensorSpec, camera: &CameraCommon) -> (CameraModel, bool) {
    match spec {
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
        SensorSpec::Laser { .. } => unreachable!("called for cameras only"),
    }
}

/// `(mount pose, on_robot)` of a sensor; applies the perturbation of fixed cameras.
fn mount_pose(
    m: &Mount,
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

pub(super) fn quat(q: &UnitQuaternion<f64>) -> Quaternion<f64> {
    *q.quaternion()
}

pub(super) fn tf(
    parent: &str,
    child: &str,
    stamp: Nanos,
    pose: &Isometry3<f64>,
) -> TransformStamped {
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
