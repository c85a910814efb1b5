//! One session, one pass in time order, as the robot ran it: every scan through the laser
//! people tracker, every camera frame through the face detector, the sound block ending at
//! each frame through GCC-PHAT, and each system variant of [`super::params::VARIANTS`]
//! stepped on the same percepts (the pan-tilt unit is where the logged system turned it: an
//! offline replay cannot turn a camera). Then the scores ([`super::score`]), the
//! direction-of-arrival blocks of every acoustic condition and the correlogram
//! ([`super::doa`]), cached as the rows of [`super::tables`].

use anyhow::Context;
use image::RgbImage;

use super::params::{Params, VARIANTS};
use super::score::{self, FrameRecord};
use super::tables::{self as t, FaceFrameRow, FaceRow, SkipRow};
use crate::anchoring::attention::Command;
use crate::anchoring::fusion::LegTrack;
use crate::anchoring::system::{LegFront, SoundFront, Spoken, StepInput, System, SystemParams};
use crate::anchoring::view::CameraView;
use crate::frames::Skips;
use crate::frames::audio;
use crate::frames::laser::{LaserOptions, scans};
use crate::frames::{camera, truth};
use crate::geometry::camera::CameraModel;
use crate::groundtruth::biron::{ATTENTION_TOPIC, BIRON_TOPIC, UTTERANCES_TOPIC, UtteranceTruth};
use crate::laser::points::ScanGeometry;
use crate::laser::tracker::TrackerParams;
use crate::log::msgs::CameraInfo;
use crate::log::{Decoders, SessionLog, TfBuffer};
use crate::progress::Progress;
use crate::report::rows::Rows;
use crate::run::{Session, SessionTables};
use crate::time::Nanos;
use crate::vision::colortrack::{BinImage, ColorSpace};
use crate::vision::faces::{Face, FaceDetector, FaceParams, grey_from_rgb};
use crate::vision::view::ImageView;

/// The topics read, after `[topics]`.
pub struct Topics {
    pub audio: String,
    pub scan: String,
    pub image: String,
    pub info: String,
}

fn first_camera(log: &SessionLog, topic: &str) -> anyhow::Result<crate::geometry::camera::Pinhole> {
    let mut dec = Decoders::new();
    if let Some(m) = log.messages_on(&[topic])?.next() {
        let m = m?;
        let info: CameraInfo = dec.typed(log, &m)?;
        return match info.model()? {
            CameraModel::Pinhole(p) => Ok(p),
            _ => anyhow::bail!(
                "{}: {topic}: the BIRON camera must be a pinhole",
                log.path().display()
            ),
        };
    }
    anyhow::bail!("{}: no CameraInfo on {topic}", log.path().display())
}

/// Leg tracks after every scan: `(stamp, tracks)`.
fn leg_tracks(
    log: &SessionLog,
    topic: &str,
    t0: Nanos,
    skips: &mut Skips,
) -> anyhow::Result<Vec<(Nanos, Vec<LegTrack>)>> {
    let opts = LaserOptions {
        fixed_frame: Some("map".into()),
        ..LaserOptions::default()
    };
    let mut front = LegFront::new(TrackerParams::default());
    let mut out = Vec::new();
    let mut it = scans(log, topic, &opts)?;
    for f in &mut it {
        let f = f?;
        let geometry = ScanGeometry::of(&f.scan);
        let ts = f.stamp.0.saturating_sub(t0.0) as f64 * 1e-9;
        let tracks = front.scan(ts, &f.scan.ranges, &geometry, f.pose.as_ref());
        out.push((f.stamp, tracks));
    }
    skips.merge(it.skips().clone());
    Ok(out)
}

fn spoken_at(utt: &[UtteranceTruth], t0: Nanos, t: f64, dt: f64) -> Vec<Spoken> {
    let secs = |ns: u64| ns.saturating_sub(t0.0) as f64 * 1e-9;
    utt.iter()
        .filter(|u| secs(u.start_ns) <= t && secs(u.end_ns) > t - 2.0 * dt)
        .map(|u| Spoken {
            index: u.index,
            start: secs(u.start_ns),
            end: secs(u.end_ns),
            command: match u.kind.as_str() {
                "greeting" => Some(Command::Greeting),
                "goodbye" => Some(Command::Goodbye),
                _ => None,
            },
            mouth: [u.mouth[0], u.mouth[1]],
        })
        .collect()
}

/// Process one session into its tables.
pub fn process(
    s: &Session,
    p: &Params,
    topics: &Topics,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let log = &s.log;
    let mut skips = Skips::new();
    bar.set_message("audio");
    let (nominal, sk) = audio::read(log, &topics.audio)?;
    skips.merge(sk);
    let t0 = nominal.start;
    let (utter, sk) = truth::utterances(log, UTTERANCES_TOPIC)?;
    skips.merge(sk);
    let utt: Vec<UtteranceTruth> = utter
        .iter()
        .next()
        .map(|(_, f)| f.utterances.clone())
        .unwrap_or_default();
    let (gt, sk) = truth::biron(log, BIRON_TOPIC)?;
    skips.merge(sk);
    let (logged, sk) = truth::attention_states(log, ATTENTION_TOPIC)?;
    skips.merge(sk);
    bar.set_message("laser");
    let legs = leg_tracks(log, &topics.scan, t0, &mut skips)?;
    let tf = TfBuffer::from_log(log, 0.5)?;
    let model = first_camera(log, &topics.info)?;
    let sys_params = SystemParams::default();
    let mut sound = SoundFront::new(&sys_params)?;
    let mut detector = FaceDetector::new(FaceParams::default())?;
    let mut systems: Vec<System> = VARIANTS
        .iter()
        .map(|(_, m)| System::new(sys_params, *m))
        .collect();
    let fs = f64::from(nominal.sample_rate);
    let block = (sys_params.sound_block_s * fs) as usize;
    let mut frames = Vec::new();
    let mut face_rows = Vec::new();
    let mut face_frames = Vec::new();
    let mut next_scan = 0usize;
    let mut prev = Nanos(0);
    bar.set_message("frames");
    let mut cam = camera::frames(log, &topics.image, None)?;
    for f in &mut cam {
        let f = f?;
        let k = ((f.stamp.0.saturating_sub(t0.0)) as f64 * 1e-9 * p.rate_hz).round() as i64;
        let t = k as f64 / p.rate_hz;
        let pose = tf
            .lookup("map", "camera_optical", f.stamp)
            .with_context(|| {
                format!("{}: camera pose at {} ns", log.path().display(), f.stamp.0)
            })?;
        let base = tf.lookup("map", "base_link", f.stamp)?;
        let mic = tf.lookup("map", "microphones", f.stamp)?;
        let view = CameraView {
            model: model.clone(),
            pose,
        };
        let found = detect(&mut detector, &f.rgb)?;
        let rgb_view = ImageView::rgb(&f.rgb)?;
        let bins = BinImage::new(rgb_view, ColorSpace::Hs)?;
        let end = (t * fs).round() as usize;
        let percept = if end >= block && end <= nominal.channels[0].len() {
            Some(sound.block(
                t,
                &nominal.channels[0][end - block..end],
                &nominal.channels[1][end - block..end],
            )?)
        } else {
            None
        };
        let mut latest = None;
        while next_scan < legs.len() && legs[next_scan].0 <= f.stamp {
            if legs[next_scan].0 > prev {
                latest = Some(&legs[next_scan].1);
            }
            next_scan += 1;
        }
        prev = f.stamp;
        let spoken = spoken_at(&utt, t0, t, 1.0 / p.rate_hz);
        let yaw = base.rotation.euler_angles().2;
        let robot = [base.translation.x, base.translation.y, yaw];
        let mics = [mic.translation.x, mic.translation.y, mic.translation.z];
        let truth_frame = gt.nearest(f.stamp, 20_000_000).cloned();
        let mut records = Vec::new();
        for sys in &mut systems {
            let out = sys.step(&StepInput {
                t,
                robot,
                mics,
                legs: latest.map(Vec::as_slice),
                view: &view,
                faces: &found,
                bins: &bins,
                sound: percept,
                spoken: &spoken,
            });
            records.push(score::record(sys, &out, t, percept.map(|p| p.active)));
        }
        if let Some(tr) = &truth_frame {
            let (rows, falses) = score::faces(k, tr, &found, p);
            face_frames.push(FaceFrameRow {
                k,
                detections: found.len() as i64,
                false_faces: falses,
            });
            face_rows.extend(rows);
        }
        frames.push(FrameRecord {
            k,
            t,
            stamp: f.stamp,
            truth: truth_frame,
            variants: records,
        });
        bar.inc(1);
    }
    skips.merge(cam.into_skips());
    bar.set_message("scores");
    let mut out = score::tables(&frames, &logged, p)?;
    bar.set_message("direction of arrival");
    let grid = super::doa::grid_streams(log, &mut skips)?;
    let mics = super::doa::Mics::at(&tf, t0)?;
    let doa_rows = super::doa::blocks(&grid, &utt, &mics, &sys_params.gcc, p)?;
    out.insert(t::DOA.into(), super::tables::DoaRow::frame(&doa_rows)?);
    let gram: RgbImage = super::doa::correlogram(&nominal, &utt, &mics, p)?;
    out.insert(
        t::CORRELOGRAM.into(),
        crate::report::columns::image_table(&gram)?,
    );
    out.insert(t::FACES.into(), FaceRow::frame(&face_rows)?);
    out.insert(t::FACE_FRAMES.into(), FaceFrameRow::frame(&face_frames)?);
    let skip_rows: Vec<SkipRow> = skips
        .rows()
        .into_iter()
        .map(|r| SkipRow {
            topic: r.topic,
            count: r.count as i64,
            first_error: r.first_error,
        })
        .collect();
    out.insert(t::SKIPS.into(), SkipRow::frame(&skip_rows)?);
    Ok(out)
}

fn detect(det: &mut FaceDetector, rgb: &RgbImage) -> anyhow::Result<Vec<Face>> {
    let grey = grey_from_rgb(ImageView::rgb(rgb)?)?;
    let view = ImageView::new(&grey, rgb.width() as usize, rgb.height() as usize, 1)?;
    Ok(det.detect(view)?)
}
