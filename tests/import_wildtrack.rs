//! `log::import::wildtrack`: a hand-made dataset in the WILDTRACK format whose projections are
//! known in closed form (7 cameras on a line, looking along +y, at 1.5 m), imported and read
//! back through the same calibration code the pipelines use; then the real dataset (SKIPPED
//! when `../shared/real/wildtrack` is absent).

use crate::common;

use std::f64::consts::FRAC_PI_2;
use std::path::Path;

use nalgebra::Point3;
use peopletrack::frames::rig;
use peopletrack::groundtruth::{PEOPLE_TOPIC, PeopleFrame};
use peopletrack::log::import::wildtrack::{self, Intrinsics};
use peopletrack::log::msgs::Detection2DArray;
use peopletrack::log::{SessionLog, TfBuffer, read_topic};

const F: f64 = 1000.0;

/// Camera k at (k − 3, −10, 1.5) m looking along +y: rvec (π/2, 0, 0) maps world (x, y, z) to
/// camera (x, −z, y); tvec = −R·C (cm). A point (x, y, z) is seen at
/// u = 960 + F (x − (k − 3)) / (y + 10), v = 540 + F (1.5 − z) / (y + 10).
fn write_fixture(dir: &Path, frames: &[(u32, f64)], bad_view: bool) {
    for sub in ["extrinsic", "intrinsic_zero", "intrinsic_original"] {
        std::fs::create_dir_all(dir.join("calibrations").join(sub)).expect("dir");
    }
    std::fs::create_dir_all(dir.join("annotations_positions")).expect("dir");
    for (k, name) in wildtrack::CAMERAS.iter().enumerate() {
        let cx = k as f64 - 3.0;
        let extr = format!(
            "<?xml version=\"1.0\"?>\n<opencv_storage>\n<rvec>\n  {FRAC_PI_2} 0 0\n </rvec>\n\
             <tvec>\n {} 150 1000\n</tvec>\n</opencv_storage>\n",
            -100.0 * cx
        );
        std::fs::write(
            dir.join(format!("calibrations/extrinsic/extr_{name}.xml")),
            extr,
        )
        .expect("write");
        for (sub, dist) in [
            ("intrinsic_zero", "0 0 0 0 0"),
            ("intrinsic_original", "-0.4 0.6 0 0 -0.7"),
        ] {
            let intr = format!(
                "<?xml version=\"1.0\"?>\n<opencv_storage>\n<camera_matrix type_id=\"opencv-matrix\">\n\
                 <rows>3</rows><cols>3</cols><dt>d</dt>\n<data>{F} 0.0 960 0.0 {F} 540 0.0 0.0 1.0</data></camera_matrix>\n\
                 <distortion_coefficients type_id=\"opencv-matrix\">\n<rows>5</rows><cols>1</cols><dt>d</dt>\n\
                 <data>\n {dist}</data></distortion_coefficients>\n</opencv_storage>\n"
            );
            std::fs::write(
                dir.join(format!("calibrations/{sub}/intr_{name}.xml")),
                intr,
            )
            .expect("write");
        }
    }
    for &(frame, x) in frames {
        // person 7 at (x, 0) on the ground, 1.8 m tall, 0.4 m wide: boxes in cameras 0–2
        let position = 360 * 480 + ((x + 3.0) / 0.025).round() as u64;
        let mut views = Vec::new();
        for k in 0..7usize {
            if k < 3 {
                let u = 960.0 + F * (x - (k as f64 - 3.0)) / 10.0;
                views.push(format!(
                    "{{\"viewNum\": {k}, \"xmin\": {}, \"ymin\": 510, \"xmax\": {}, \"ymax\": 690}}",
                    u - 20.0,
                    u + 20.0
                ));
            } else {
                views.push(format!(
                    "{{\"viewNum\": {k}, \"xmin\": -1, \"ymin\": -1, \"xmax\": -1, \"ymax\": -1}}"
                ));
            }
        }
        let mut people = vec![format!(
            "{{\"personID\": 7, \"positionID\": {position}, \"views\": [{}]}}",
            views.join(", ")
        )];
        if bad_view {
            people.push(
                "{\"personID\": 8, \"positionID\": 5, \"views\": [{\"viewNum\": 9, \"xmin\": 1, \"ymin\": 1, \"xmax\": 2, \"ymax\": 2}]}"
                    .to_string(),
            );
        }
        std::fs::write(
            dir.join(format!("annotations_positions/{frame:08}.json")),
            format!("[{}]", people.join(",\n")),
        )
        .expect("write");
    }
}

#[test]
fn fixture_projections_land_on_the_annotated_boxes() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path().join("wildtrack");
    write_fixture(&dir, &[(0, 0.0), (5, 0.5)], true);
    let ds = wildtrack::read(&dir, Intrinsics::Zero).expect("read");
    assert_eq!(ds.frames.len(), 2);
    assert_eq!(ds.skipped, 2, "person 8 has viewNum 9 in both frames");
    assert!(
        ds.first_skip
            .as_deref()
            .unwrap_or("")
            .contains("00000000.json")
    );
    assert_eq!(ds.invisible_views, 8);
    let check = wildtrack::projection_check(&ds);
    assert_eq!(check.boxes, 6);
    assert!(
        check.median_foot_px < 1e-6 && check.median_head_px < 1e-6,
        "{check:?}"
    );
    // the distorted set does not fit the boxes
    let orig =
        wildtrack::projection_check(&wildtrack::read(&dir, Intrinsics::Original).expect("read"));
    assert!(orig.median_foot_px > 1.0, "{orig:?}");

    let out = tmp.path().join("wt.mcap");
    let s = wildtrack::write(&ds, &dir, Intrinsics::Zero, &out).expect("write");
    assert_eq!((s.frames, s.people_frames, s.boxes), (2, 2, 6));

    // read back through the pipelines' calibration code
    let log = SessionLog::open(&out).expect("open");
    let tf = TfBuffer::from_log(&log, 0.1).expect("tf");
    let cams: Vec<(String, String)> = (0..7)
        .map(|k| {
            let n = wildtrack::camera_name(k);
            (n.clone(), format!("/{n}/camera_info"))
        })
        .collect();
    let views = rig::views(&log, &tf, &cams, "map").expect("views");
    let truth: Vec<PeopleFrame> = log
        .messages_on(&[PEOPLE_TOPIC])
        .expect("gt")
        .map(|m| serde_json::from_slice(&m.expect("msg").data).expect("json"))
        .collect();
    assert_eq!(truth.len(), 2);
    for (f, gt) in truth.iter().enumerate() {
        let p = &gt.people[0];
        let x = [0.0, 0.5][f];
        assert_eq!(p.id, 7);
        assert!((p.x - x).abs() < 1e-9 && p.y.abs() < 1e-9, "{p:?}");
        assert!((p.height - 1.8).abs() < 1e-9, "height {}", p.height);
        assert!((p.radius - 0.2).abs() < 1e-9, "radius {}", p.radius);
        assert!(
            (p.vx - 1.0).abs() < 1e-9 && p.vy.abs() < 1e-9,
            "0.5 m in 0.5 s: {p:?}"
        );
        assert_eq!(p.cameras.len(), 3);
        for v in &p.cameras {
            let k = (0..7)
                .find(|&k| wildtrack::camera_name(k) == v.camera)
                .expect("camera");
            let b = v.bbox.expect("box");
            let foot = views[k].project(&Point3::new(p.x, p.y, 0.0)).expect("foot");
            let head = views[k]
                .project(&Point3::new(p.x, p.y, p.height))
                .expect("head");
            let cx = 0.5 * (b[0] + b[2]);
            assert!(
                (foot.x - cx).abs() < 1e-6 && (foot.y - b[3]).abs() < 1e-6,
                "{foot} {b:?}"
            );
            assert!(
                (head.x - cx).abs() < 1e-6 && (head.y - b[1]).abs() < 1e-6,
                "{head} {b:?}"
            );
            let hp = v.head_px.expect("head px");
            assert!((hp[0] - cx).abs() < 1e-6 && (hp[1] - 510.0).abs() < 1e-6);
        }
    }
    // detections: every box, as centre and size, at the frame's stamp
    let dets: Vec<_> = read_topic::<Detection2DArray>(&log, "/cvlab2/detections")
        .expect("topic")
        .map(|r| r.expect("det"))
        .collect();
    assert_eq!(dets.len(), 2);
    assert_eq!(
        dets[1].0.0 - dets[0].0.0,
        500_000_000,
        "frames 0 and 5 at 10 fps"
    );
    let d = &dets[1].1.detections[0];
    // camera 1 at x = -2: u = 960 + 1000 (0.5 + 2) / 10
    assert!(
        (d.center_x - 1210.0).abs() < 1e-9 && (d.center_y - 600.0).abs() < 1e-9,
        "{d:?}"
    );
    assert!((d.size_x - 40.0).abs() < 1e-9 && (d.size_y - 180.0).abs() < 1e-9);
    assert!(
        read_topic::<Detection2DArray>(&log, "/idiap3/detections")
            .expect("topic")
            .all(|r| r.expect("det").1.detections.is_empty())
    );
}

#[test]
fn a_missing_calibration_names_the_file() {
    let tmp = tempfile::tempdir().expect("tmp");
    write_fixture(tmp.path(), &[(0, 0.0)], false);
    std::fs::remove_file(tmp.path().join("calibrations/extrinsic/extr_IDIAP2.xml")).expect("rm");
    let e = wildtrack::read(tmp.path(), Intrinsics::Zero).expect_err("missing");
    assert!(e.to_string().contains("extr_IDIAP2.xml"), "{e}");
    std::fs::write(
        tmp.path().join("calibrations/extrinsic/extr_IDIAP2.xml"),
        "<rvec>1 2</rvec>",
    )
    .expect("write");
    let e = wildtrack::read(tmp.path(), Intrinsics::Zero).expect_err("short");
    assert!(
        e.to_string().contains("extr_IDIAP2.xml") && e.to_string().contains("<rvec>"),
        "{e}"
    );
}

/// The real dataset: the boxes fit `intrinsic_zero` (measured here over all 42,721 boxes:
/// ground point to box bottom centre median 6.7 px, 1.8 m above it to the top centre 6.7 px;
/// with `intrinsic_original`'s distortion 19 px and 19 px) better than the raw distortion.
#[test]
fn real_wildtrack_boxes_fit_intrinsic_zero() {
    let Some(dir) = common::real("wildtrack") else {
        return;
    };
    let zero = wildtrack::read(&dir, Intrinsics::Zero).expect("read");
    assert_eq!(zero.frames.len(), 400);
    let z = wildtrack::projection_check(&zero);
    let o =
        wildtrack::projection_check(&wildtrack::read(&dir, Intrinsics::Original).expect("read"));
    eprintln!("intrinsic_zero {z:?}\nintrinsic_original {o:?}");
    assert!(z.median_foot_px < 10.0 && z.median_head_px < 10.0, "{z:?}");
    assert!(z.median_foot_px < o.median_foot_px && z.median_head_px < o.median_head_px);
}

/// The real dataset's motion statistic behind `accel_sigma_mps2` in
/// `pipelines/real/s004_wildtrack.toml`, against an independent computation (a Python script
/// over the pipeline's `gt` table, frames 0–199): 4,362 second differences 0.5 s apart, median
/// 0.158 m (= 0.025 √40 on the 2.5 cm grid), σ_a = √2 · 0.158 / (√(2 ln 2) · 0.25) = 0.76 m/s².
#[test]
fn real_wildtrack_motion_on_the_development_frames() {
    let Some(dir) = common::real("wildtrack") else {
        return;
    };
    let ds = wildtrack::read(&dir, Intrinsics::Zero).expect("read");
    let m = wildtrack::motion_check(&ds.frames[..wildtrack::DEVELOPMENT_FRAMES]).expect("motion");
    assert_eq!(m.samples, 4362, "{m:?}");
    assert!((m.period_s - 0.5).abs() < 1e-12, "{m:?}");
    assert!((m.median_m - 0.025 * 40f64.sqrt()).abs() < 1e-9, "{m:?}");
    assert!((m.accel_sigma_mps2 - 0.76).abs() < 0.005, "{m:?}");
}
