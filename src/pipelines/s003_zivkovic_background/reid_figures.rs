//! Re-identification figures for the first scored session: the identity timeline per person
//! (truth vs the paper's model, on ground-truth local tracks, the whole session) and the
//! paper's fig. 4b (the first three feature components of one local track over its frames:
//! the top region's channel-normalised r, g, b of the person's pixels).

use super::params::ReidParams;
use super::reid::{FRAMES_TABLE, PERSON, ReidFrameRow};
use super::reid_features::{Observation, Space, observations};
use super::reid_methods::{PAPER, Training, labels};
use crate::report::Figure;
use crate::report::figure::{FigureKind, LinePlot, Mark, Panels, Series};
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products};

/// Points every `step` seconds along each observation's span at height `y(o)`, one series per
/// colour key.
fn segments(
    obs: &[&Observation],
    key: impl Fn(usize) -> usize,
    y: impl Fn(&Observation) -> f64,
    name: &str,
) -> Vec<Series> {
    let mut keys: Vec<usize> = (0..obs.len()).map(&key).collect();
    keys.sort_unstable();
    keys.dedup();
    keys.iter()
        .map(|&k| {
            let mut pts = Vec::new();
            for o in (0..obs.len()).filter(|i| key(*i) == k).map(|i| obs[i]) {
                let n = ((o.span.leave - o.span.enter) / 0.25).ceil().max(1.0) as usize;
                for j in 0..=n {
                    let t = o.span.enter + (o.span.leave - o.span.enter) * j as f64 / n as f64;
                    pts.push((t, y(o)));
                }
            }
            Series::points(format!("{name} {k}"), pts, k).with_mark(Mark::Points)
        })
        .collect()
}

fn timeline(obs: &[&Observation], est: &[usize], session: &str) -> Figure {
    let truth = |o: &Observation| o.truth.unwrap_or(0) as f64;
    let plot = |title: &str, series: Vec<Series>| {
        Figure::new(
            "panel",
            title,
            FigureKind::Lines(LinePlot {
                x_label: "time (s)".into(),
                y_label: "true person".into(),
                series,
                ..LinePlot::default()
            }),
        )
    };
    let by_truth = segments(obs, |i| obs[i].truth.unwrap_or(0) as usize, truth, "person");
    let by_label = segments(obs, |i| est[i], truth, "label");
    Figure::new(
        "reid_timeline",
        format!("Identity timeline ({session}): truth vs the paper's model"),
        FigureKind::Panels(Panels {
            columns: 1,
            panels: vec![
                plot("truth", by_truth),
                plot("paper's model (ADF), ground-truth local tracks", by_label),
            ],
        }),
    )
}

/// Fig. 4b: the first three components (region 1's r, g, b) of the longest track's frames.
fn features_over_time(rows: &[ReidFrameRow], obs: &Observation, session: &str) -> Figure {
    let frames: Vec<&ReidFrameRow> = rows
        .iter()
        .filter(|r| {
            r.source == "truth"
                && r.pixels == PERSON
                && r.id == obs.id
                && r.t_s >= obs.span.enter
                && r.t_s <= obs.span.leave
        })
        .collect();
    let series = ["r", "g", "b"]
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let pts = frames
                .iter()
                .map(|r| (r.t_s, Space::Normalised.of(r.means(), r.frame_means())[c]))
                .collect();
            Series::line(format!("region 1 {name}"), pts, c)
        })
        .collect();
    Figure::new(
        "reid_features_fig4b",
        format!(
            "Fig. 4b: top-region r, g, b of the person's pixels over one track ({session}, person {})",
            obs.id
        ),
        FigureKind::Lines(LinePlot {
            x_label: "time (s)".into(),
            y_label: "channel / frame mean".into(),
            series,
            ..LinePlot::default()
        }),
    )
}

pub(super) fn products(
    ctx: &Aggregate,
    p: &ReidParams,
    products: &mut Products,
) -> anyhow::Result<()> {
    let Some((info, df)) = ctx
        .sessions
        .iter()
        .filter(|(info, _)| p.datasets.contains(&info.dataset))
        .find_map(|(info, t)| t.get(FRAMES_TABLE).map(|df| (info, df)))
    else {
        return Ok(());
    };
    let rows = ReidFrameRow::read(df)?;
    let all = observations(&rows, "truth", p);
    let obs: Vec<&Observation> = all
        .iter()
        .filter(|o| o.feature(PAPER.feature).is_some())
        .collect();
    if obs.is_empty() {
        return Ok(());
    }
    let est = labels(&obs, &PAPER, p.nn_threshold, &Training::default())?.unwrap_or_default();
    products.figures.push(timeline(&obs, &est, &info.name));
    if let Some(longest) = obs
        .iter()
        .max_by_key(|o| (o.feature_frames(PAPER.feature), std::cmp::Reverse(o.id)))
    {
        products
            .figures
            .push(features_over_time(&rows, longest, &info.name));
    }
    Ok(())
}
