//! The session in time order, in closed loop: audio chunks, laser scans, and at each camera
//! frame the image taken with the pan-tilt unit where the attention system last turned it,
//! then the system's step on exactly what was logged (the JPEG decoded back, the scans'
//! ranges, the nominal audio as 16-bit samples), its state, and the ground truth.

use image::RgbImage;
use nalgebra::{Isometry3, Translation3};

use super::audio::{AudioSetup, Condition};
use super::script::{Script, Stage};
use super::{LASER_XZ, grid_topic, info_topic, pose, tf, truth};
use crate::anchoring::attention::Command;
use crate::anchoring::ptu::{CAMERA_HEIGHT_M, PanTilt};
use crate::anchoring::system::{LegFront, SoundFront, Spoken, StepInput, System, SystemParams};
use crate::anchoring::view::CameraView;
use crate::anchoring::{Modalities, fusion::LegTrack};
use crate::geometry::{
    self,
    camera::{CameraModel, Pinhole},
};
use crate::groundtruth::biron::{self as gt, AttentionState};
use crate::groundtruth::{self as gtp, PeopleFrame};
use crate::laser::points::ScanGeometry;
use crate::laser::tracker::TrackerParams;
use crate::log::msgs::{
    AudioDataStamped, AudioInfo, CameraInfo, CompressedImage, Header, JointState, LaserScan,
    TfMessage,
};
use crate::log::{ChannelId, SessionWriter};
use crate::progress::Progress;
use crate::rng;
use crate::synth::laser::{LaserSpec, scan};
use crate::synth::render::{Camera, FrameInput};
use crate::synth::scenario::BironSpec;
use crate::synth::session::{PreviewData, SynthError};
use crate::synth::world::{Primitive, World};
use crate::time::Nanos;
use crate::vision::colortrack::{BinImage, ColorSpace};
use crate::vision::faces::{FaceDetector, FaceParams, grey_from_rgb};
use crate::vision::view::ImageView;

/// Audio chunk length (frames): 64 ms at 16 kHz.
pub const CHUNK_FRAMES: usize = 1024;
/// JPEG quality of the camera images.
const JPEG_QUALITY: u8 = 90;
/// Laser: SICK-like 180° at 0.5°, 8 m, 1 cm noise, 10 Hz, first scan 30 ms in.
const LASER_RATE_HZ: f64 = 10.0;
const LASER_PHASE_S: f64 = 0.03;

/// What a run reads.
pub(super) struct Run<'a> {
    pub spec: &'a BironSpec,
    pub world: &'a World,
    pub script: &'a Script,
    pub stage: &'a Stage,
    pub setup: &'a AudioSetup,
    pub conditions: &'a [Condition],
    pub seed: u64,
    pub t0: Nanos,
}

struct Channels {
    tf: ChannelId,
    scan: ChannelId,
    image: ChannelId,
    info: ChannelId,
    joints: ChannelId,
    state: ChannelId,
    people: ChannelId,
    biron: ChannelId,
    /// `(condition, channel)`: `/audio` (the nominal condition) and every grid cell.
    audio: Vec<(usize, ChannelId)>,
}

/// The camera's `world_from_optical` for a robot at `base` and the unit at `p`.
pub fn camera_pose(base: &Isometry3<f64>, p: PanTilt) -> Isometry3<f64> {
    let body = geometry::pose_xyz_rpy([0.0, 0.0, CAMERA_HEIGHT_M], [0.0, -p.tilt, p.pan]);
    base * body * Isometry3::from_parts(Translation3::identity(), geometry::body_from_optical())
}

fn laser_spec() -> LaserSpec {
    LaserSpec {
        fov: std::f64::consts::PI,
        increment: 0.5f64.to_radians(),
        range_min: 0.05,
        range_max: 8.0,
        noise_m: 0.01,
        dropout: 0.0,
    }
}

impl Run<'_> {
    fn at(&self, t: f64) -> Nanos {
        Nanos(self.t0.0 + (t * 1e9).round() as u64)
    }

    fn base(&self) -> Isometry3<f64> {
        let r = self.stage.robot;
        pose(r[0], r[1], 0.0, r[2])
    }

    fn channels(&self, w: &mut SessionWriter) -> Result<Channels, SynthError> {
        let tf_static = w.add_ros2::<TfMessage>("/tf_static")?;
        let base = self.base();
        let laser = pose(LASER_XZ[0], 0.0, LASER_XZ[1], 0.0);
        w.write(
            tf_static,
            self.t0,
            &TfMessage {
                transforms: vec![
                    tf("map", "odom", self.t0, &Isometry3::identity()),
                    tf("odom", "base_link", self.t0, &base),
                    tf("base_link", "laser", self.t0, &laser),
                    tf(
                        "base_link",
                        "microphones",
                        self.t0,
                        &pose(self.setup.forward_m, 0.0, self.setup.height_m, 0.0),
                    ),
                ],
            },
        )?;
        let mut audio = Vec::new();
        let mut topics: Vec<(usize, String)> = self
            .conditions
            .iter()
            .enumerate()
            .map(|(i, c)| (i, grid_topic(c.rt60_s, c.snr_db)))
            .collect();
        if let Some(i) = self
            .conditions
            .iter()
            .position(|c| [c.rt60_s, c.snr_db] == self.spec.nominal)
        {
            topics.insert(0, (i, "/audio".to_string()));
        }
        for (i, topic) in topics {
            let info = w.add_ros2::<AudioInfo>(&info_topic(&topic))?;
            w.write(
                info,
                self.t0,
                &AudioInfo {
                    channels: 2,
                    sample_rate: self.setup.sample_rate,
                    sample_format: "S16LE".into(),
                    bitrate: self.setup.sample_rate * 2 * 16,
                    coding_format: "wave".into(),
                },
            )?;
            audio.push((i, w.add_ros2::<AudioDataStamped>(&topic)?));
        }
        let utter = w.add_json(
            gt::UTTERANCES_TOPIC,
            gt::UTTERANCES_SCHEMA,
            &gt::json_schema(gt::UTTERANCES_SCHEMA),
        )?;
        w.write_json(
            utter,
            self.t0,
            &truth::utterances(self.script, self.t0, |t| self.at(t)),
        )?;
        Ok(Channels {
            tf: w.add_ros2::<TfMessage>("/tf")?,
            scan: w.add_ros2::<LaserScan>("/scan")?,
            image: w.add_ros2::<CompressedImage>("/camera/image_raw/compressed")?,
            info: w.add_ros2::<CameraInfo>("/camera/camera_info")?,
            joints: w.add_ros2::<JointState>("/ptu/joint_states")?,
            state: w.add_json(
                gt::ATTENTION_TOPIC,
                gt::ATTENTION_SCHEMA,
                &gt::json_schema(gt::ATTENTION_SCHEMA),
            )?,
            people: w.add_json(
                gtp::PEOPLE_TOPIC,
                gtp::PEOPLE_SCHEMA,
                gtp::PEOPLE_JSON_SCHEMA,
            )?,
            biron: w.add_json(
                gt::BIRON_TOPIC,
                gt::BIRON_SCHEMA,
                &gt::json_schema(gt::BIRON_SCHEMA),
            )?,
            audio,
        })
    }

    /// Everyone present at `t` as primitives (faces painted), and their states.
    fn scene(&self, t: f64) -> Vec<Primitive> {
        let mut prims = Vec::new();
        for v in &self.script.visitors {
            if let Some((s, yaw)) = v.at(t) {
                v.body.primitives_with_face(&s, yaw, &mut prims);
            }
        }
        prims
    }

    /// Write the whole session (see the module doc); returns the preview of the middle frame.
    pub fn write(
        &self,
        w: &mut SessionWriter,
        bar: &dyn Progress,
    ) -> Result<PreviewData, SynthError> {
        let ch = self.channels(w)?;
        let dur = self.stage.duration;
        let steps = (dur * self.spec.rate_hz).floor() as usize;
        bar.set_length(steps as u64);
        let mut lp = Loop::new(self)?;
        let mut preview = None;
        for k in 0..steps {
            let t = k as f64 / self.spec.rate_hz;
            lp.chunks_until(self, w, &ch, t)?;
            lp.scans_until(self, w, &ch, t)?;
            let (frame, biron) = lp.frame(self, w, &ch, k, t)?;
            if k == steps / 2 {
                preview = Some(self.preview(t, &frame.rgb, frame.width, frame.height, &biron));
            }
            bar.inc(1);
        }
        lp.chunks_until(self, w, &ch, dur)?;
        preview
            .ok_or_else(|| SynthError::Scenario("a BIRON session needs at least one frame".into()))
    }

    fn write_chunk(
        &self,
        w: &mut SessionWriter,
        ch: &Channels,
        k: usize,
    ) -> Result<(), SynthError> {
        let fs = f64::from(self.setup.sample_rate);
        let stamp = self.at(k as f64 * CHUNK_FRAMES as f64 / fs);
        let log = self.at((k + 1) as f64 * CHUNK_FRAMES as f64 / fs + 0.003);
        for &(i, id) in &ch.audio {
            let c = &self.conditions[i];
            let frames = &c.samples[2 * k * CHUNK_FRAMES..2 * (k + 1) * CHUNK_FRAMES];
            let data: Vec<u8> = frames.iter().flat_map(|s| s.to_le_bytes()).collect();
            w.write(
                id,
                log,
                &AudioDataStamped {
                    header: Header::new(stamp, "microphones"),
                    data,
                },
            )?;
        }
        Ok(())
    }

    fn preview(&self, t: f64, rgb: &[u8], w: u32, h: u32, biron: &gt::BironFrame) -> PreviewData {
        let img = RgbImage::from_raw(w, h, rgb.to_vec()).unwrap_or_default();
        PreviewData {
            t,
            cameras: vec![("camera".to_string(), img, Vec::new())],
            scan_points: Vec::new(),
            people: biron
                .people
                .iter()
                .map(|p| gtp::PersonTruth {
                    id: p.id,
                    x: p.x,
                    y: p.y,
                    vx: 0.0,
                    vy: 0.0,
                    height: p.mouth[2] + 0.17,
                    head_z: p.mouth[2] + 0.05,
                    radius: 0.2,
                    legs: [[p.x, p.y]; 2],
                    leg_radius: 0.065,
                    cameras: Vec::new(),
                })
                .collect(),
            robot: self.stage.robot,
            sensors: vec![("camera".to_string(), self.stage.camera)],
            world: self.world.clone(),
        }
    }
}

fn scen(e: impl std::fmt::Display) -> SynthError {
    SynthError::Scenario(e.to_string())
}

/// The closed loop's state between steps: the robot's attention system and its percept
/// fronts, the pan-tilt unit, what has been written so far, the true attention.
struct Loop {
    model: Pinhole,
    cam: Camera,
    laser: LaserSpec,
    laser_pose: Isometry3<f64>,
    geometry: ScanGeometry,
    params: SystemParams,
    system: System,
    legs: LegFront,
    sound: SoundFront,
    faces: FaceDetector,
    mic: (Vec<f32>, Vec<f32>),
    mics: [f64; 3],
    truth: truth::TrueAttention,
    ptu: PanTilt,
    next_chunk: usize,
    next_scan: usize,
    latest: Option<Vec<LegTrack>>,
}

impl Loop {
    fn new(run: &Run) -> Result<Loop, SynthError> {
        let model = Pinhole::from_fov(run.spec.camera[0], run.spec.camera[1], run.spec.hfov_deg);
        let laser = laser_spec();
        let geometry = ScanGeometry {
            angle_min: laser.angle_min(),
            angle_increment: laser.increment,
            range_min: laser.range_min,
            range_max: laser.range_max,
        };
        let params = SystemParams::default();
        let nominal = run
            .conditions
            .iter()
            .position(|c| [c.rt60_s, c.snr_db] == run.spec.nominal)
            .unwrap_or(0);
        let a = run.setup.mic(run.stage.robot, 0);
        let b = run.setup.mic(run.stage.robot, 1);
        Ok(Loop {
            cam: Camera::new("camera", CameraModel::Pinhole(model.clone()), 2.0, None, 0),
            model,
            laser,
            laser_pose: run.base() * pose(LASER_XZ[0], 0.0, LASER_XZ[1], 0.0),
            geometry,
            system: System::new(params, Modalities::ALL),
            legs: LegFront::new(TrackerParams::default()),
            sound: SoundFront::new(&params).map_err(scen)?,
            faces: FaceDetector::new(FaceParams::default()).map_err(scen)?,
            params,
            mic: deinterleave(&run.conditions[nominal].samples),
            mics: [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, a[2]],
            truth: truth::TrueAttention::default(),
            ptu: PanTilt::default(),
            next_chunk: 0,
            next_scan: 0,
            latest: None,
        })
    }

    /// Audio chunks that ended by `t`.
    fn chunks_until(
        &mut self,
        run: &Run,
        w: &mut SessionWriter,
        ch: &Channels,
        t: f64,
    ) -> Result<(), SynthError> {
        let fs = f64::from(run.setup.sample_rate);
        while (self.next_chunk + 1) * CHUNK_FRAMES <= (t * fs).round() as usize {
            run.write_chunk(w, ch, self.next_chunk)?;
            self.next_chunk += 1;
        }
        Ok(())
    }

    /// Scans up to `t`, each written and fed to the laser people tracker.
    fn scans_until(
        &mut self,
        run: &Run,
        w: &mut SessionWriter,
        ch: &Channels,
        t: f64,
    ) -> Result<(), SynthError> {
        let spec = &self.laser;
        loop {
            let ts = LASER_PHASE_S + self.next_scan as f64 / LASER_RATE_HZ;
            if ts > t {
                return Ok(());
            }
            let prims = run.scene(ts);
            let key = rng::hash(run.seed, &[self.next_scan as u64, 0x1a5e]);
            let (ranges, _) = scan(spec, &self.laser_pose, &[&run.world.statics, &prims], key);
            let stamp = run.at(ts);
            w.write(
                ch.scan,
                Nanos(stamp.0 + 5_000_000),
                &LaserScan {
                    header: Header::new(stamp, "laser"),
                    angle_min: spec.angle_min() as f32,
                    angle_max: (spec.angle_min() + (spec.beams() - 1) as f64 * spec.increment)
                        as f32,
                    angle_increment: spec.increment as f32,
                    time_increment: 0.0,
                    scan_time: (1.0 / LASER_RATE_HZ) as f32,
                    range_min: spec.range_min as f32,
                    range_max: spec.range_max as f32,
                    ranges: ranges.clone(),
                    intensities: Vec::new(),
                },
            )?;
            let ts_logged = (stamp.0 - run.t0.0) as f64 * 1e-9;
            self.latest =
                Some(
                    self.legs
                        .scan(ts_logged, &ranges, &self.geometry, Some(&self.laser_pose)),
                );
            self.next_scan += 1;
        }
    }

    /// Camera frame `k` at `t`: render with the unit where it is, write the image, its pose
    /// and the joint states; the system's step on the decoded JPEG; the attention state and
    /// the ground truth. The unit turns for the next frame.
    fn frame(
        &mut self,
        run: &Run,
        w: &mut SessionWriter,
        ch: &Channels,
        k: usize,
        t: f64,
    ) -> Result<(crate::synth::render::Frame, gt::BironFrame), SynthError> {
        let stamp = run.at(t);
        let prims = run.scene(t);
        let cam_pose = camera_pose(&run.base(), self.ptu);
        let frame = self.cam.render(&FrameInput {
            world: run.world,
            dynamic: &prims,
            shadows: &[],
            t,
            pose: cam_pose,
            noise_key: rng::hash(run.seed, &[k as u64, 0xca]),
        });
        let jpeg = self.write_frame(run, w, ch, &frame, stamp, &cam_pose)?;
        let rgb = image::load_from_memory_with_format(&jpeg, image::ImageFormat::Jpeg)
            .map_err(scen)?
            .to_rgb8();
        let view = CameraView {
            model: self.model.clone(),
            pose: cam_pose,
        };
        let rgb_view = ImageView::rgb(&rgb).map_err(scen)?;
        let grey = grey_from_rgb(rgb_view).map_err(scen)?;
        let grey_view =
            ImageView::new(&grey, rgb.width() as usize, rgb.height() as usize, 1).map_err(scen)?;
        let found = self.faces.detect(grey_view).map_err(scen)?;
        let bins = BinImage::new(rgb_view, ColorSpace::Hs).map_err(scen)?;
        let fs = f64::from(run.setup.sample_rate);
        let block = (self.params.sound_block_s * fs) as usize;
        let end = (t * fs).round() as usize;
        let percept = if end >= block && end <= self.mic.0.len() {
            Some(
                self.sound
                    .block(
                        t,
                        &self.mic.0[end - block..end],
                        &self.mic.1[end - block..end],
                    )
                    .map_err(scen)?,
            )
        } else {
            None
        };
        let spoken = spoken(run.script, t, 1.0 / run.spec.rate_hz);
        let out = self.system.step(&StepInput {
            t,
            robot: run.stage.robot,
            mics: self.mics,
            legs: self.latest.take().as_deref(),
            view: &view,
            faces: &found,
            bins: &bins,
            sound: percept,
            spoken: &spoken,
        });
        w.write_json(
            ch.state,
            Nanos(stamp.0 + 30_000_000),
            &state_of(&self.system, &out, stamp, t),
        )?;
        let (people, biron) = self
            .truth
            .step(run.script, run.stage, t, stamp, &view, &frame.ids);
        w.write_json(
            ch.people,
            stamp,
            &PeopleFrame {
                stamp_ns: stamp.0,
                people,
            },
        )?;
        w.write_json(ch.biron, stamp, &biron)?;
        self.ptu = out.ptu;
        Ok((frame, biron))
    }

    /// Write a frame's TF, joint states, JPEG and camera info; returns the JPEG bytes.
    fn write_frame(
        &self,
        run: &Run,
        w: &mut SessionWriter,
        ch: &Channels,
        frame: &crate::synth::render::Frame,
        stamp: Nanos,
        cam_pose: &Isometry3<f64>,
    ) -> Result<Vec<u8>, SynthError> {
        let mut jpeg = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, JPEG_QUALITY)
            .encode(
                &frame.rgb,
                frame.width,
                frame.height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| SynthError::Encode {
                camera: "camera".into(),
                reason: e.to_string(),
            })?;
        let header = Header::new(stamp, "camera_optical");
        let base_from_optical = run.base().inverse() * cam_pose;
        let soon = Nanos(stamp.0 + 1_000_000);
        w.write(
            ch.tf,
            soon,
            &TfMessage {
                transforms: vec![tf("base_link", "camera_optical", stamp, &base_from_optical)],
            },
        )?;
        w.write(
            ch.joints,
            soon,
            &JointState {
                header: Header::new(stamp, "base_link"),
                name: vec!["pan".into(), "tilt".into()],
                position: vec![self.ptu.pan, self.ptu.tilt],
                velocity: Vec::new(),
                effort: Vec::new(),
            },
        )?;
        let log = Nanos(stamp.0 + 15_000_000);
        w.write(
            ch.image,
            log,
            &CompressedImage {
                header: header.clone(),
                format: "jpeg".into(),
                data: jpeg.clone(),
            },
        )?;
        w.write(
            ch.info,
            log,
            &CameraInfo::from_model(&CameraModel::Pinhole(self.model.clone()), header),
        )?;
        Ok(jpeg)
    }
}

/// The two channels of interleaved samples as floats in [−1, 1).
pub fn deinterleave(samples: &[i16]) -> (Vec<f32>, Vec<f32>) {
    let l = samples
        .iter()
        .step_by(2)
        .map(|&s| f32::from(s) / 32768.0)
        .collect();
    let r = samples
        .iter()
        .skip(1)
        .step_by(2)
        .map(|&s| f32::from(s) / 32768.0)
        .collect();
    (l, r)
}

/// Utterances under way at `t` or ended within the last two steps, for the dialog stand-in.
fn spoken(script: &Script, t: f64, dt: f64) -> Vec<Spoken> {
    script
        .utterances
        .iter()
        .enumerate()
        .filter(|(_, u)| u.start <= t && u.end > t - 2.0 * dt)
        .filter_map(|(i, u)| {
            let v = script.visitors.iter().find(|v| v.body.id == u.speaker)?;
            let (s, yaw) = v.at(u.start)?;
            let m = v.mouth(&s, yaw);
            Some(Spoken {
                index: i,
                start: u.start,
                end: u.end,
                command: match u.kind {
                    super::script::Kind::Greeting => Some(Command::Greeting),
                    super::script::Kind::Goodbye => Some(Command::Goodbye),
                    super::script::Kind::Talk => None,
                },
                mouth: [m[0], m[1]],
            })
        })
        .collect()
}

/// `/attention/state` of a step.
pub fn state_of(
    system: &System,
    out: &crate::anchoring::system::StepOutput,
    stamp: Nanos,
    t: f64,
) -> AttentionState {
    AttentionState {
        stamp_ns: stamp.0,
        mode: out.mode.name().to_string(),
        focus: out.focus,
        pan_deg: out.ptu.pan.to_degrees(),
        tilt_deg: out.ptu.tilt.to_degrees(),
        anchors: system
            .fusion
            .anchors
            .iter()
            .map(|a| {
                let [l, f, to, v] = a.states(t);
                let (speaking, looking) = system.fusion.cues(a, t);
                gt::AnchorState {
                    id: a.id,
                    x: a.position[0],
                    y: a.position[1],
                    height: a.height_m,
                    legs: l.name().into(),
                    face: f.name().into(),
                    torso: to.name().into(),
                    voice: v.name().into(),
                    category: crate::anchoring::attention::category(speaking, looking),
                }
            })
            .collect(),
        sound_anchor: out.sound_anchor,
    }
}
