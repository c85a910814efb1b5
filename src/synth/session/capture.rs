//! Every sensor at its own rate, in time order: the schedule of captures, the scene at each
//! instant (people and moving background), each camera's frame (image, camera info, exact
//! person mask, and what it saw of each person) and each laser scan, then the ground truth of
//! the instant. Also picks the instant the preview shows.

use image::RgbImage;
use nalgebra::{Isometry3, Point3};

use super::rig::{CameraSensor, Channels, LaserSensor, Rig, SensorRuntime};
use super::truth;
use super::types::{PreviewData, Scene, Session, SynthError};
use crate::groundtruth::CameraView;
use crate::log::SessionWriter;
use crate::log::msgs::{CameraInfo, CompressedImage, Header, Image, LaserScan};
use crate::progress::Progress;
use crate::rng;
use crate::synth::laser::scan;
use crate::synth::person::PersonState;
use crate::synth::render::{Frame, FrameInput};
use crate::synth::scenario::ImageFormat;
use crate::synth::world::{PERSON_BASE, Primitive};
use crate::time::Nanos;

/// Deterministic latency (ns) of a message.
fn latency(seed: u64, sensor: usize, k: u64, lo_ms: f64, hi_ms: f64) -> u64 {
    let u = f64::from(rng::unit(rng::hash(seed, &[0x1a7e, sensor as u64, k])));
    ((lo_ms + (hi_ms - lo_ms) * u) * 1e6) as u64
}

/// Sensor schedule `(time in ns, sensor index, frame number)`, sorted.
pub(super) fn schedule(sensors: &[SensorRuntime], seed: u64, dur: f64) -> Vec<(u64, usize, u64)> {
    let mut events: Vec<(u64, usize, u64)> = Vec::new();
    for (i, sen) in sensors.iter().enumerate() {
        let period = 1.0 / sen.rate();
        // cameras are triggered together (as multi-camera rigs are); lasers free-run with a
        // small offset
        let phase = match sen {
            SensorRuntime::Camera(_) => 0.0,
            SensorRuntime::Laser(_) => {
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
    events
}

/// Capture every sensor of `rig` over the session, with the ground truth of every instant a
/// sensor captured. Returns the preview: the first frame of each sensor from the middle
/// event on, and the ground truth at the middle event.
pub(super) fn capture_all(
    w: &mut SessionWriter,
    ses: &Session,
    rig: &Rig,
    ch: &Channels,
    bar: &dyn Progress,
) -> Result<PreviewData, SynthError> {
    let events = schedule(&rig.sensors, ses.seed, ses.s.scenario.duration_s);
    bar.set_length(events.len() as u64);
    let mid = events.get(events.len() / 2).map_or(0, |e| e.0);
    let mut previewed: Vec<bool> = vec![false; rig.sensors.len()];
    let mut preview = PreviewData {
        t: 0.0,
        cameras: Vec::new(),
        scan_points: Vec::new(),
        people: Vec::new(),
        robot: [0.0; 3],
        sensors: Vec::new(),
        world: ses.world.clone(),
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
        let rs = ses.robot_track.state(t);
        let scene = ses.scene(t, rs.pose(), &mut dynamic);
        // views[slot]: what each camera that captured this instant saw of person `states[slot]`
        let mut views: Vec<Vec<CameraView>> = vec![Vec::new(); scene.states.len()];
        for &(_, si, n) in &events[e..group_end] {
            let take_preview = t_ns >= mid && !previewed[si];
            if take_preview {
                previewed[si] = true;
            }
            let preview = take_preview.then_some(&mut preview);
            match &rig.sensors[si] {
                SensorRuntime::Camera(c) => {
                    ses.capture_camera(w, c, (si, n), &scene, &mut views, preview)?;
                }
                SensorRuntime::Laser(l) => ses.capture_laser(w, l, (si, n), &scene, preview)?,
            }
            bar.inc(1);
        }
        // ground truth at this instant, with the views of the cameras that captured it
        let gt_people = truth::people(ses, &scene, views);
        if t_ns == mid {
            preview.t = t;
            preview.people = gt_people.clone();
            preview.robot = [rs.x, rs.y, rs.yaw];
        }
        truth::write(w, ses, ch, &scene, gt_people)?;
        e = group_end;
    }
    Ok(preview)
}

impl Session<'_> {
    /// The scene at `t` with the robot at `base`; `dynamic` is the buffer its primitives live in.
    pub(super) fn scene<'d>(
        &self,
        t: f64,
        base: Isometry3<f64>,
        dynamic: &'d mut Vec<Primitive>,
    ) -> Scene<'d> {
        let people = self.people;
        let states: Vec<(usize, PersonState)> = people
            .iter()
            .enumerate()
            .filter_map(|(i, a)| a.track.state(t).map(|st| (i, st)))
            .collect();
        dynamic.clear();
        self.world.moving_at(t, dynamic);
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
        Scene {
            t,
            stamp: self.clock.at(t),
            base,
            states,
            dynamic,
            per_person,
            shadows,
        }
    }

    /// Render frame `n` of camera `si`, write its image, camera info and mask, and add what it
    /// saw of each person to `views`; fills the preview when given one.
    fn capture_camera(
        &self,
        w: &mut SessionWriter,
        c: &CameraSensor,
        (si, n): (usize, u64),
        scene: &Scene,
        views: &mut [Vec<CameraView>],
        preview: Option<&mut PreviewData>,
    ) -> Result<(), SynthError> {
        let stamp = scene.stamp;
        let (frame, pose) = self.render_camera(c, (si, n), scene);
        let log = Nanos(stamp.0 + latency(self.seed, si, n, 8.0, 25.0));
        write_frame(w, c, &frame, Header::new(stamp, c.frame_id.clone()), log)?;
        // ground-truth views of this camera
        let mut seen_here = Vec::new();
        for (slot, view) in self.camera_views(c, &pose, &frame, scene) {
            seen_here.push((self.people[scene.states[slot].0].body.id, view.clone()));
            views[slot].push(view);
        }
        if let Some(preview) = preview {
            let (wdt, hgt) = (frame.width, frame.height);
            let img = RgbImage::from_raw(wdt, hgt, frame.rgb.clone()).ok_or_else(|| {
                SynthError::Encode {
                    camera: c.frame_id.clone(),
                    reason: "frame size".into(),
                }
            })?;
            preview.cameras.push((c.frame_id.clone(), img, seen_here));
            preview
                .sensors
                .push((c.frame_id.clone(), pose.translation.vector.into()));
        }
        Ok(())
    }

    /// Frame `n` of camera `si` at `scene`, and the camera's pose in `map`.
    pub(super) fn render_camera(
        &self,
        c: &CameraSensor,
        (si, n): (usize, u64),
        scene: &Scene,
    ) -> (Frame, Isometry3<f64>) {
        let pose = if c.on_robot {
            scene.base * c.mount
        } else {
            c.mount
        };
        let frame = c.cam.render(&FrameInput {
            world: self.world,
            dynamic: scene.dynamic,
            shadows: &scene.shadows,
            t: scene.t,
            pose,
            noise_key: rng::hash(self.seed, &[n, si as u64]),
        });
        (frame, pose)
    }

    /// Scan `n` of laser `si` at `scene` (ranges as logged), and the laser's pose in `map`.
    pub(super) fn cast_scan(
        &self,
        l: &LaserSensor,
        (si, n): (usize, u64),
        scene: &Scene,
    ) -> (Vec<f32>, Isometry3<f64>) {
        let pose = if l.on_robot {
            scene.base * l.mount
        } else {
            l.mount
        };
        let (ranges, _) = scan(
            &l.spec,
            &pose,
            &[&self.world.statics, scene.dynamic],
            rng::hash(self.seed, &[n, si as u64, 0x1a5e]),
        );
        (ranges, pose)
    }

    /// What camera `c` at `pose` saw of each present person: `(slot in states, view)` for
    /// every person some of whose pixels would be in the image without occluders.
    fn camera_views(
        &self,
        c: &CameraSensor,
        pose: &Isometry3<f64>,
        frame: &Frame,
        scene: &Scene,
    ) -> Vec<(usize, CameraView)> {
        let cam = &c.cam;
        let wdt = frame.width;
        let cam_from_world = pose.inverse();
        let mut out = Vec::new();
        for (slot, ((i, st), prims)) in scene.states.iter().zip(&scene.per_person).enumerate() {
            let body = &self.people[*i].body;
            let id = body.object();
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
            let full = cam.unoccluded_pixels(pose, prims);
            if full == 0 {
                continue;
            }
            let head = cam
                .model
                .project(&(cam_from_world * body.head_top(st)))
                .filter(|p| cam.model.in_image(p));
            let view = CameraView {
                camera: c.frame_id.clone(),
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
            out.push((slot, view));
        }
        out
    }

    /// Scan `n` of laser `si` and write it; fills the preview's scan points when given one.
    fn capture_laser(
        &self,
        w: &mut SessionWriter,
        l: &LaserSensor,
        (si, n): (usize, u64),
        scene: &Scene,
        preview: Option<&mut PreviewData>,
    ) -> Result<(), SynthError> {
        let spec = &l.spec;
        let stamp = scene.stamp;
        let (ranges, pose) = self.cast_scan(l, (si, n), scene);
        if let Some(preview) = preview {
            preview.scan_points = ranges
                .iter()
                .enumerate()
                .filter(|(_, r)| r.is_finite())
                .map(|(b, r)| {
                    let a = spec.angle_min() + b as f64 * spec.increment;
                    let p =
                        pose * Point3::new(f64::from(*r) * a.cos(), f64::from(*r) * a.sin(), 0.0);
                    [p.x, p.y]
                })
                .collect();
            preview
                .sensors
                .push((l.frame_id.clone(), pose.translation.vector.into()));
        }
        let log = Nanos(stamp.0 + latency(self.seed, si, n, 3.0, 8.0));
        w.write(
            l.channel,
            log,
            &LaserScan {
                header: Header::new(stamp, l.frame_id.clone()),
                angle_min: spec.angle_min() as f32,
                angle_max: (spec.angle_min() + (spec.beams() - 1) as f64 * spec.increment) as f32,
                angle_increment: spec.increment as f32,
                time_increment: 0.0,
                scan_time: (1.0 / l.rate) as f32,
                range_min: spec.range_min as f32,
                range_max: spec.range_max as f32,
                ranges,
                intensities: Vec::new(),
            },
        )?;
        Ok(())
    }
}

/// Write a camera frame: the image (raw or JPEG), the camera info and, when the camera
/// records it, the exact person mask — all with `header` at log time `log`.
fn write_frame(
    w: &mut SessionWriter,
    c: &CameraSensor,
    frame: &Frame,
    header: Header,
    log: Nanos,
) -> Result<(), SynthError> {
    let (wdt, hgt) = (frame.width, frame.height);
    match c.format {
        ImageFormat::Raw => w.write(
            c.channels.0,
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
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut buf, c.quality)
                .encode(&frame.rgb, wdt, hgt, image::ExtendedColorType::Rgb8)
                .map_err(|e| SynthError::Encode {
                    camera: c.frame_id.clone(),
                    reason: e.to_string(),
                })?;
            w.write(
                c.channels.0,
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
        c.channels.1,
        log,
        &CameraInfo::from_model(&c.cam.model, header.clone()),
    )?;
    if c.mask
        && let Some(ch) = c.channels.2
    {
        let data: Vec<u8> = frame
            .ids
            .iter()
            .map(|id| if *id >= PERSON_BASE { 255 } else { 0 })
            .collect();
        w.write(ch, log, &mono8(header.clone(), wdt, hgt, data))?;
    }
    if let Some(ch) = c.skin_channel {
        let data: Vec<u8> = frame
            .skin
            .iter()
            .map(|s| if *s { 255 } else { 0 })
            .collect();
        w.write(ch, log, &mono8(header.clone(), wdt, hgt, data))?;
    }
    if let Some(ch) = c.id_channel {
        let data: Vec<u8> = frame.ids.iter().map(|&id| person_id_pixel(id)).collect();
        w.write(ch, log, &mono8(header, wdt, hgt, data))?;
    }
    Ok(())
}

/// A pixel of the per-person id mask: the person's id for a person's object id, 0 for anything
/// else, 255 for ids that do not fit.
fn person_id_pixel(object: u32) -> u8 {
    if object > PERSON_BASE {
        u8::try_from(object - PERSON_BASE).unwrap_or(u8::MAX)
    } else {
        0
    }
}

/// A `mono8` ground-truth mask image.
fn mono8(header: Header, width: u32, height: u32, data: Vec<u8>) -> Image {
    Image {
        header,
        height,
        width,
        encoding: "mono8".into(),
        is_bigendian: 0,
        step: width,
        data,
    }
}
