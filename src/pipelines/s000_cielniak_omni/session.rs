//! The per-session stage: the webcams' hat measurements (section 3), the calibration marks and
//! the simulator's truth when the log has them, and the omni camera's features (4.2–4.3).

use super::omni;
use super::params::Params;
use super::sources::{for_each_frame, rig_camera};
use super::tables::{CameraRow, CameraTruthRow, HatRow, SkipRow, TargetRow, TruthRow, frame};
use crate::calib::external;
use crate::frames::{Skips, truth};
use crate::groundtruth::{PEOPLE_TOPIC, TARGETS_TOPIC};
use crate::log::{SessionLog, TfBuffer};
use crate::progress::Progress;
use crate::run::{Session, SessionTables};

/// All per-session tables of one log.
pub fn process(s: &Session, p: &Params, bar: &dyn Progress) -> anyhow::Result<SessionTables> {
    let log = &s.log;
    let tf = TfBuffer::from_log(log, 1e6)?;
    let t0 = log
        .summary()
        .statistics
        .as_ref()
        .map_or(crate::Nanos(0), |st| st.start);
    bar.set_length((p.webcams.len() + 1) as u64);
    let mut skips = Skips::new();
    let (cameras, hats) = webcams(log, &tf, t0, p, bar, &mut skips)?;
    let (targets, truth) = ground_truth(log, &mut skips)?;
    bar.set_message("omni features");
    let (omni, pose) = omni::features_of(log, &tf, t0, p, &mut skips)?;
    bar.inc(1);
    let skipped: Vec<SkipRow> = skips
        .rows()
        .into_iter()
        .map(|r| SkipRow {
            topic: r.topic,
            count: i64::try_from(r.count).unwrap_or(i64::MAX),
            first_error: r.first_error,
        })
        .collect();
    Ok(SessionTables::from([
        ("cameras".to_string(), frame(&cameras)?),
        ("camera_truth".to_string(), frame(&camera_truth(log))?),
        ("hats".to_string(), frame(&hats)?),
        ("targets".to_string(), frame(&targets)?),
        ("truth".to_string(), frame(&truth)?),
        ("omni".to_string(), frame(&omni)?),
        ("omni_pose".to_string(), frame(&[pose])?),
        ("skips".to_string(), frame(&skipped)?),
    ]))
}

/// Nominal parameters of each webcam (TF and camera_info), and the hat blobs in its frames.
fn webcams(
    log: &SessionLog,
    tf: &TfBuffer,
    t0: crate::Nanos,
    p: &Params,
    bar: &dyn Progress,
    skips: &mut Skips,
) -> anyhow::Result<(Vec<CameraRow>, Vec<HatRow>)> {
    let (mut cameras, mut hats) = (Vec::new(), Vec::new());
    for (k, name) in p.webcams.iter().enumerate() {
        bar.set_message(&format!("hats in {name}"));
        let cam = rig_camera(log, tf, name, t0)?;
        let (info, pose) = (&cam.info, cam.world_from_camera);
        let z = pose.rotation * nalgebra::Vector3::z();
        cameras.push(CameraRow {
            camera: name.clone(),
            x: pose.translation.x,
            y: pose.translation.y,
            heading: z.y.atan2(z.x),
            range: 2.0 * (f64::from(info.width) / 2.0 / info.k[0]).atan(),
            width: f64::from(info.width),
        });
        for_each_frame(log, name, skips, |stamp, img| {
            if let Some(b) = external::find_hue_blob(
                &img,
                (p.hat_hue_deg[0], p.hat_hue_deg[1]),
                p.hat_min_saturation,
                p.hat_min_value,
                p.hat_min_area,
            ) {
                hats.push(HatRow {
                    stamp,
                    camera: k as i64,
                    u: b.u,
                    v: b.v,
                    area: i64::from(b.area),
                    whole: !b.touches_border,
                });
            }
            Ok(())
        })?;
        bar.inc(1);
    }
    Ok((cameras, hats))
}

/// The calibration marks and (when present) the simulator's people, in stamp order.
fn ground_truth(
    log: &SessionLog,
    skips: &mut Skips,
) -> anyhow::Result<(Vec<TargetRow>, Vec<TruthRow>)> {
    let (marks, s) = truth::targets(log, TARGETS_TOPIC)?;
    skips.merge(s);
    let targets = marks
        .items()
        .iter()
        .flat_map(|f| {
            f.targets.iter().map(|t| TargetRow {
                stamp: f.stamp_ns as i64,
                x: t.x,
                y: t.y,
            })
        })
        .collect();
    let (people, s) = truth::people(log, PEOPLE_TOPIC)?;
    skips.merge(s);
    let truth = people
        .items()
        .iter()
        .flat_map(|f| {
            f.people.iter().map(|q| TruthRow {
                stamp: f.stamp_ns as i64,
                id: i64::from(q.id),
                x: q.x,
                y: q.y,
            })
        })
        .collect();
    Ok((targets, truth))
}

/// The webcams' true poses from the log's `peopletrack.truth` metadata (none in a real log).
fn camera_truth(log: &SessionLog) -> Vec<CameraTruthRow> {
    let meta = log
        .summary()
        .metadata
        .iter()
        .find(|m| m.name == "peopletrack.truth");
    let list: Vec<serde_json::Value> = meta
        .and_then(|m| m.entries.get("cameras"))
        .and_then(|c| serde_json::from_str(c).ok())
        .unwrap_or_default();
    list.iter().map(camera_truth_row).collect()
}

fn camera_truth_row(v: &serde_json::Value) -> CameraTruthRow {
    let xyz = |i: usize| v["true_xyz"][i].as_f64().unwrap_or(f64::NAN);
    CameraTruthRow {
        camera: v["name"].as_str().unwrap_or_default().to_string(),
        true_x: xyz(0),
        true_y: xyz(1),
        true_yaw_deg: v["true_yaw_deg"].as_f64().unwrap_or(f64::NAN),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_camera_truth_entry_reads_its_fields_and_missing_ones_as_nan() {
        let v: serde_json::Value = serde_json::from_str(
            r#"{"name": "cam_1", "true_xyz": [1.5, -2.0, 1.2], "true_yaw_deg": 90.0}"#,
        )
        .expect("json");
        assert_eq!(
            camera_truth_row(&v),
            CameraTruthRow {
                camera: "cam_1".into(),
                true_x: 1.5,
                true_y: -2.0,
                true_yaw_deg: 90.0
            }
        );
        let r = camera_truth_row(&serde_json::json!({"name": "cam_2"}));
        assert_eq!(r.camera, "cam_2");
        assert!(r.true_x.is_nan() && r.true_y.is_nan() && r.true_yaw_deg.is_nan());
    }
}
