//! The appearance model as a product: per-frame position estimates (`estimates.csv`), and the
//! saved / loaded model file.

use anyhow::Context;
use serde::{Deserialize, Serialize};

use super::correlations::FEATURES;
use super::params::Params;
use super::tables::{self, OmniRow, PoseRow};
use crate::calib::external;
use crate::learn::mlp::{Regressor, TrainSpec};
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products};
use crate::table_row;

/// The `kind` of a saved model.
pub const MODEL_KIND: &str = "s000_cielniak_omni";

/// A saved appearance model: the network, its scaling, and where it came from.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AppearanceModel {
    pub kind: String,
    pub version: u32,
    pub features: Vec<String>,
    pub regressor: Regressor,
    pub train: TrainSpec,
    pub samples: usize,
    pub sessions: Vec<String>,
    pub tool_version: String,
    pub git_commit: String,
}

/// The model named by `p.model`, if any; a file of another kind is refused.
pub fn load(p: &Params) -> anyhow::Result<Option<AppearanceModel>> {
    if p.model.is_empty() {
        return Ok(None);
    }
    let text =
        std::fs::read_to_string(&p.model).with_context(|| format!("reading model {}", p.model))?;
    let m: AppearanceModel = serde_json::from_str(&text)
        .with_context(|| format!("model {} is not an appearance model", p.model))?;
    anyhow::ensure!(
        m.kind == MODEL_KIND,
        "model {} is a `{}` model, not `{}`",
        p.model,
        m.kind,
        MODEL_KIND
    );
    Ok(Some(m))
}

table_row! {
    /// One frame's estimate: a row of `estimates.csv`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct EstimateRow {
        pub session: String,
        pub stamp_ns: i64,
        pub bearing_deg: f64,
        pub distance_m: f64,
        pub x_m: f64,
        pub y_m: f64,
    }
}

/// The estimate of the model's distance `d` at the panorama angle `angle` from a camera at
/// `pose`: bearing in the map, position.
pub fn estimate(session: &str, o: &OmniRow, pose: &PoseRow, d: f64) -> EstimateRow {
    let b = external::wrap(pose.yaw + o.angle);
    EstimateRow {
        session: session.into(),
        stamp_ns: o.stamp,
        bearing_deg: b.to_degrees(),
        distance_m: d,
        x_m: pose.x + d * b.cos(),
        y_m: pose.y + d * b.sin(),
    }
}

/// Per-frame estimates of the appearance model on every omni frame with a person: session,
/// stamp, bearing (deg, map frame), distance (m) and position (m, map frame), as CSV.
pub fn estimates_csv(ctx: &Aggregate, model: &Regressor) -> anyhow::Result<Vec<u8>> {
    let mut rows = Vec::new();
    for (session, tables) in ctx.sessions {
        let omni: Vec<OmniRow> = tables::read(tables, "omni")?;
        if !omni.iter().any(|o| o.valid) {
            continue;
        }
        let pose = tables::read::<PoseRow>(tables, "omni_pose")?
            .first()
            .copied()
            .context("no omni pose")?;
        let name = session.path.display().to_string();
        for o in omni.iter().filter(|o| o.valid) {
            let d = model.predict(&[o.width, o.apparent_distance, o.pixels]);
            rows.push(estimate(&name, o, &pose, d));
        }
    }
    Ok(Table::new("estimates", "", EstimateRow::frame(&rows)?).to_csv()?)
}

/// estimates.csv from `general`, and (when trained here and asked for) the saved model.
pub fn run(
    ctx: &Aggregate,
    p: &Params,
    general: Regressor,
    trained_on: Option<usize>,
    out: &mut Products,
) -> anyhow::Result<()> {
    out.artifacts
        .push(("estimates.csv".into(), estimates_csv(ctx, &general)?));
    let Some(samples) = trained_on.filter(|_| !p.save_model.is_empty()) else {
        return Ok(());
    };
    let model = AppearanceModel {
        kind: MODEL_KIND.into(),
        version: 1,
        features: FEATURES.iter().map(|s| (*s).to_string()).collect(),
        regressor: general,
        train: p.spec(),
        samples,
        sessions: ctx
            .sessions
            .iter()
            .map(|(s, _)| s.path.display().to_string())
            .collect(),
        tool_version: ctx.provenance.tool_version.clone(),
        git_commit: ctx.provenance.git_commit.clone(),
    };
    out.artifacts.push((
        p.save_model.clone().into(),
        serde_json::to_vec_pretty(&model)?,
    ));
    out.summary.push(format!(
        "General model trained on all {samples} frames saved to out/s000_cielniak_omni/{}.",
        p.save_model
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_estimate_is_the_distance_along_the_bearing_from_the_camera() {
        let o = OmniRow {
            stamp: 42,
            valid: true,
            width: 1.0,
            apparent_distance: 2.0,
            pixels: 3.0,
            angle: std::f64::consts::FRAC_PI_4,
        };
        let pose = PoseRow {
            x: 1.0,
            y: -1.0,
            yaw: std::f64::consts::FRAC_PI_4,
        };
        let e = estimate("a.mcap", &o, &pose, 2.0);
        assert_eq!((e.session.as_str(), e.stamp_ns), ("a.mcap", 42));
        assert!((e.bearing_deg - 90.0).abs() < 1e-12);
        assert!((e.x_m - 1.0).abs() < 1e-12 && (e.y_m - 1.0).abs() < 1e-12);
        // the bearing wraps into (−180°, 180°]
        let back = OmniRow { angle: 3.0, ..o };
        let e = estimate("a.mcap", &back, &pose, 1.0);
        assert!(
            (e.bearing_deg
                - (3.0 + std::f64::consts::FRAC_PI_4 - std::f64::consts::TAU).to_degrees())
            .abs()
                < 1e-9
        );
    }

    #[test]
    fn a_model_of_another_kind_is_refused_naming_the_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("m.json");
        std::fs::write(&path, "{\"kind\": \"other\"}").expect("write");
        let p = Params {
            model: path.display().to_string(),
            ..Params::default()
        };
        let e = load(&p).expect_err("refused");
        assert!(format!("{e:#}").contains("m.json"), "{e:#}");
        assert!(load(&Params::default()).expect("none").is_none());
    }
}
