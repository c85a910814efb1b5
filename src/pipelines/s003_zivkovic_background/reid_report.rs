//! Re-identification, the report (seed 003 §IV–V): the cached per-frame rows grouped into
//! local tracks (`reid_features`), the training split fitted (`reid_methods::Training`), then
//! each clip of every scored session filtered online in order of the tracks' ends by every
//! method (`reid_methods`) on ground-truth local tracks and on the system's own, and scored
//! by `eval::reid`. Tables: `reid` (per session, clip, source, method), `reid_observations`
//! (every observation's label: every metric can be recomputed from it), `reid_retrieval`;
//! its runs go on to `reid_summary` (the pooled table, the t-tests across sessions, the
//! training split's fitted values and the paper's goals).

use std::collections::BTreeMap;

use super::params::{ClipParams, Params, ReidParams};
use super::reid::{FRAMES_TABLE, ReidFrameRow};
use super::reid_features::{Feature, Observation, observations};
use super::reid_methods::{METHODS, Method, Training, labels};
use crate::eval::reid::{retrieval, score};
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products};
use crate::table_row;

/// Both sources of local tracks: ground truth (re-identification alone), the system's own.
pub(super) const SOURCES: [&str; 2] = ["truth", "system"];

table_row! {
    /// A row of the `reid` table.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct ReidRow {
        pub dataset: String,
        pub session: String,
        pub clip: String,
        pub source: String,
        pub method: String,
        /// Observations (local tracks) of the clip with the method's feature.
        pub observations: i64,
        /// Observations of the clip without it (no frame gave the method's pixels).
        pub no_feature: i64,
        pub no_person: i64,
        pub true_people: i64,
        pub found_people: i64,
        pub people_error: i64,
        pub wrongly_new: i64,
        pub merged: i64,
        pub people_wrong: i64,
        pub misidentified: i64,
        pub misidentified_pct: f64,
        pub pair_precision: f64,
        pub pair_recall: f64,
        pub pair_f1: f64,
        pub adjusted_rand: f64,
    }
}

table_row! {
    /// A row of the `reid_observations` table: one observation of one run.
    #[derive(Debug, Clone, PartialEq)]
    struct ObservationRow {
        dataset: String,
        session: String,
        clip: String,
        source: String,
        method: String,
        track: i64,
        enter_s: f64,
        leave_s: f64,
        frames: i64,
        feature_frames: i64,
        true_person: Option<i64>,
        label: Option<i64>,
    }
}

table_row! {
    /// A row of the `reid_retrieval` table.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct RetrievalRow {
        pub dataset: String,
        pub session: String,
        pub clip: String,
        pub source: String,
        pub feature: String,
        pub queries: i64,
        pub rank1: f64,
        pub map: f64,
    }
}

/// A feature variant's name in tables.
pub(super) fn feature_name(f: Feature) -> String {
    format!("{} pixels, {}", f.0.key(), f.1.name())
}

pub(super) fn in_clip(o: &Observation, c: &ClipParams) -> bool {
    c.until_s.is_none_or(|t| o.span.leave <= t)
}

/// A session's observations per source.
pub(super) struct SessionObs {
    pub dataset: String,
    pub session: String,
    /// `(source, observations)`, in [`SOURCES`] order.
    pub by_source: Vec<(&'static str, Vec<Observation>)>,
}

/// The observations of every session of the datasets `wanted` names, in session order.
pub(super) fn sessions_of(
    ctx: &Aggregate,
    wanted: &[String],
    p: &ReidParams,
) -> anyhow::Result<Vec<SessionObs>> {
    let mut out = Vec::new();
    for (info, tables) in ctx.sessions {
        if !wanted.contains(&info.dataset) {
            continue;
        }
        let Some(df) = tables.get(FRAMES_TABLE) else {
            continue;
        };
        let frames = ReidFrameRow::read(df)?;
        out.push(SessionObs {
            dataset: info.dataset.clone(),
            session: info.name.clone(),
            by_source: SOURCES
                .iter()
                .map(|s| (*s, observations(&frames, s, p)))
                .collect(),
        });
    }
    Ok(out)
}

/// The training split fitted on the ground-truth observations of its sessions.
pub(super) fn training(ctx: &Aggregate, p: &ReidParams) -> anyhow::Result<Training> {
    let split = sessions_of(ctx, &p.train_datasets, p)?;
    let truth: Vec<(String, Vec<Observation>)> = split
        .into_iter()
        .map(|s| {
            let obs = s
                .by_source
                .into_iter()
                .find(|(src, _)| *src == "truth")
                .map(|(_, o)| o)
                .unwrap_or_default();
            (s.session, obs)
        })
        .collect();
    Training::fit(&truth)
}

/// Rank-1 / mAP of a clip's scored observations, for each feature the methods use.
fn retrieval_rows(head: [&str; 4], obs: &[&Observation]) -> Vec<RetrievalRow> {
    let mut features: Vec<Feature> = METHODS.iter().map(|m| m.feature).collect();
    features.sort_unstable();
    features.dedup();
    features
        .into_iter()
        .map(|f| {
            let scored: Vec<&&Observation> = obs
                .iter()
                .filter(|o| o.truth.is_some() && o.feature(f).is_some())
                .collect();
            let truth: Vec<Option<i64>> = scored.iter().map(|o| o.truth).collect();
            let x: Vec<Vec<f64>> = scored
                .iter()
                .filter_map(|o| o.feature(f).map(|v| v.to_vec()))
                .collect();
            let r = retrieval(&x, &truth);
            RetrievalRow {
                dataset: head[0].into(),
                session: head[1].into(),
                clip: head[2].into(),
                source: head[3].into(),
                feature: feature_name(f),
                queries: r.queries as i64,
                rank1: r.rank1,
                map: r.map,
            }
        })
        .collect()
}

/// Everything the runs produce.
#[derive(Default)]
pub(super) struct Runs {
    pub rows: Vec<ReidRow>,
    observations: Vec<ObservationRow>,
    pub retrieval: Vec<RetrievalRow>,
}

/// One (session, clip, source) run of method `m` over the clip's observations `clip_obs`.
fn run_one(
    head: [&str; 4],
    clip_obs: &[&Observation],
    m: &Method,
    p: &ReidParams,
    training: &Training,
    out: &mut Runs,
) -> anyhow::Result<()> {
    let usable: Vec<&Observation> = clip_obs
        .iter()
        .copied()
        .filter(|o| o.feature(m.feature).is_some())
        .collect();
    let Some(got) = labels(&usable, m, p.nn_threshold, training)? else {
        return Ok(()); // a fitted value the run lacks: no training split
    };
    let mut label_of: BTreeMap<(i64, u64), usize> = BTreeMap::new();
    for (o, l) in usable.iter().zip(&got) {
        label_of.insert((o.id, o.span.enter.to_bits()), *l);
    }
    for o in clip_obs {
        out.observations.push(ObservationRow {
            dataset: head[0].into(),
            session: head[1].into(),
            clip: head[2].into(),
            source: head[3].into(),
            method: m.name.into(),
            track: o.id,
            enter_s: o.span.enter,
            leave_s: o.span.leave,
            frames: o.frames as i64,
            feature_frames: o.feature_frames(m.feature) as i64,
            true_person: o.truth,
            label: label_of
                .get(&(o.id, o.span.enter.to_bits()))
                .map(|l| *l as i64),
        });
    }
    let (truth, est): (Vec<i64>, Vec<usize>) = usable
        .iter()
        .zip(&got)
        .filter_map(|(o, l)| o.truth.map(|t| (t, *l)))
        .unzip();
    let s = score(&truth, &est);
    out.rows.push(ReidRow {
        dataset: head[0].into(),
        session: head[1].into(),
        clip: head[2].into(),
        source: head[3].into(),
        method: m.name.into(),
        observations: usable.len() as i64,
        no_feature: (clip_obs.len() - usable.len()) as i64,
        no_person: (usable.len() - s.observations) as i64,
        true_people: s.true_people as i64,
        found_people: s.found_people as i64,
        people_error: s.people_error,
        wrongly_new: s.wrongly_new as i64,
        merged: s.merged as i64,
        people_wrong: s.people_wrong as i64,
        misidentified: s.misidentified as i64,
        misidentified_pct: 100.0 * s.misidentified as f64 / s.observations.max(1) as f64,
        pair_precision: s.pair_precision,
        pair_recall: s.pair_recall,
        pair_f1: s.pair_f1,
        adjusted_rand: s.adjusted_rand,
    });
    Ok(())
}

/// Every (session, clip, source, method) run of the scored sessions, and retrieval.
fn runs(scored: &[SessionObs], p: &ReidParams, training: &Training) -> anyhow::Result<Runs> {
    let mut out = Runs::default();
    for s in scored {
        for (source, all) in &s.by_source {
            for clip in &p.clips {
                let obs: Vec<&Observation> = all.iter().filter(|o| in_clip(o, clip)).collect();
                let head = [
                    s.dataset.as_str(),
                    s.session.as_str(),
                    clip.name.as_str(),
                    source,
                ];
                out.retrieval.extend(retrieval_rows(head, &obs));
                for m in &METHODS {
                    run_one(head, &obs, m, p, training, &mut out)?;
                }
            }
        }
    }
    Ok(out)
}

/// The per-session tables; the runs and what the training split fitted come back for
/// `reid_summary` (`None`: no scored session).
pub(super) fn products(
    ctx: &Aggregate,
    p: &Params,
    products: &mut Products,
) -> anyhow::Result<Option<(Runs, Training)>> {
    let r = &p.reid;
    let scored = sessions_of(ctx, &r.datasets, r)?;
    if scored.is_empty() {
        return Ok(None);
    }
    let training = training(ctx, r)?;
    let runs = runs(&scored, r, &training)?;
    let clips: Vec<String> = r
        .clips
        .iter()
        .map(|c| match c.until_s {
            Some(t) => format!("{} = tracks ended by {t} s", c.name),
            None => format!("{} = the whole session", c.name),
        })
        .collect();
    products.tables.push(
        Table::new("reid", "Re-identification across local tracks (Zajdel et al.): the paper's model beside variants and baselines, per session, clip and source", ReidRow::frame(&runs.rows)?)
            .with_precision("misidentified_pct", 1)
            .with_precision("pair_precision", 3)
            .with_precision("pair_recall", 3)
            .with_precision("pair_f1", 3)
            .with_precision("adjusted_rand", 3)
            .with_note("Paper (two real clips): clip 1, two places lit alike — every person identified correctly (0 errors); clip 2, across strongly different light — one of five people wrongly identified as a new person.")
            .with_note(format!("Clips: {}. Observations are local tracks (gap > {} s splits a track, fewer than {} frames dropped), filtered in order of their end; `truth` = ground-truth boxes with visibility ≥ {}, `system` = the local tracker's tracks, each scored as the person it overlaps most (IoU ≥ local_eval.min_iou; `no_person` = tracks on no person, filtered but not scored). `no_feature` = tracks of the clip none of whose frames gave the method's pixels (the camera moving, the model warming up, or fewer than 10 pixels in a region): not filtered.", clips.join("; "), r.max_gap_s, r.min_frames, r.min_visibility))
            .with_note("Features: the mean colour of fig. 4a's three regions, split on the blob's height, of the person's pixels — the local tracker's own foreground inside the box (`paper`; `ceiling: exact masks` = the synthesizer's per-person mask; `whole box` = every pixel of the box, the feature before issue 31; `filled silhouettes` = the foreground with each row filled between its first and last pixel) — in the colour-channel-normalised space of the paper's [8] (each channel / its frame mean; `ln space` = its log, `raw RGB` = RGB / 255, `chromaticity` = each region's normalised colour / its r + g + b, [8]'s second step), averaged over the track's frames.")
            .with_note(format!("Prior as printed: a₀ = 0, κ₀ = 100, η₀ = 9, C₀ = 10⁻³·I; `prior moved` = a₀, κ₀ and C₀ fitted on the training split (table reid_prior; our addition). P_δ = 0 when a track starts before the person's previous one ended. Nearest neighbour: threshold {} (a priori) or fitted on the training split, with the same no-overlap rule. misidentified = observations not on their person under the best one-to-one label mapping; people_error = found − true; wrongly_new = people with an observation labelled as nobody's (a new individual); merged = people with an observation labelled as another person; people_wrong = either.", r.nn_threshold)),
    );
    products.tables.push(
        Table::new("reid_observations", "Re-identification, every observation of every run: the label each method gave each local track", ObservationRow::frame(&runs.observations)?)
            .with_precision("enter_s", 2)
            .with_precision("leave_s", 2)
            .with_note("label: the method's person label (1-based, in order of first use), empty when the track has no feature for the method (feature_frames = 0); true_person empty for a system track on no person. Every metric of `reid` can be recomputed from these rows."),
    );
    products.tables.push(
        Table::new("reid_retrieval", "Re-identification as retrieval: rank-1 and mAP, each scored local track querying the clip's others by feature distance", RetrievalRow::frame(&runs.retrieval)?)
            .with_precision("rank1", 3)
            .with_precision("map", 3)
            .with_note("Euclidean distance between the tracks' mean 9-D features; queries = tracks whose person has another track in the clip with the feature. Not in the paper (our addition, the usual re-identification measure)."),
    );
    Ok(Some((runs, training)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s003_zivkovic_background::reid_features::{PixelSet, Space};
    use crate::pipelines::s003_zivkovic_background::reid_methods::{Model, PriorKind};
    use crate::track::reid::Span;

    const F: Feature = (PixelSet::Person, Space::Normalised);

    /// Person `truth` seen from `enter` for 1 s, channel-normalised look `base` ± 0.02.
    fn look(truth: i64, enter: f64, base: f64, k: usize) -> Observation {
        let x: [f64; 9] = std::array::from_fn(|j| {
            base + if (j + k).is_multiple_of(2) {
                0.02
            } else {
                -0.02
            }
        });
        Observation {
            id: truth,
            truth: Some(truth),
            span: Span {
                enter,
                leave: enter + 1.0,
            },
            frames: 10,
            features: BTreeMap::from([(F, (x, 10))]),
        }
    }

    #[test]
    fn a_session_runs_every_method_and_the_training_split_moves_the_prior() {
        // two people 0.3 apart in every channel, each seen twice; the training split has two
        // others of the same kind. The printed prior (a₀ = 0, far from looks near 1) merges
        // them; moved to the training split's units it tells them apart
        let p = ReidParams {
            clips: vec![ClipParams {
                name: "all".into(),
                until_s: None,
            }],
            ..ReidParams::default()
        };
        let scored = vec![SessionObs {
            dataset: "d".into(),
            session: "d_00".into(),
            by_source: vec![(
                "truth",
                vec![
                    look(1, 0.0, 0.9, 0),
                    look(2, 10.0, 1.2, 0),
                    look(1, 20.0, 0.9, 1),
                    look(2, 30.0, 1.2, 1),
                ],
            )],
        }];
        let train = vec![look(5, 0.0, 0.8, 0), look(6, 10.0, 1.1, 0)]
            .into_iter()
            .chain([look(5, 20.0, 0.8, 1), look(6, 30.0, 1.1, 1)])
            .collect();
        let training = Training::fit(&[("t_90".into(), train)]).expect("fit");
        let got = runs(&scored, &p, &training).expect("runs");
        // one row per method, but for the moved prior on any feature other than the person's
        // channel-normalised pixels: the training split has no such looks to move it with
        let unfitted = METHODS
            .iter()
            .filter(|m| {
                m.feature != F
                    && matches!(
                        m.model,
                        Model::Adf {
                            prior: PriorKind::Trained,
                            ..
                        }
                    )
            })
            .count();
        assert_eq!(
            unfitted, 4,
            "exact, filled, chromaticity, exact chromaticity"
        );
        assert_eq!(got.rows.len(), METHODS.len() - unfitted);
        assert!(!got.rows.iter().any(|r| r.method == METHODS[8].name));
        let row = |name: &str| got.rows.iter().find(|r| r.method == name).expect(name);
        let paper = row(PAPER_NAME);
        assert_eq!(
            (paper.misidentified, paper.merged, paper.found_people),
            (2, 1, 1)
        );
        let moved = row(METHODS[1].name);
        assert_eq!(
            (moved.misidentified, moved.people_wrong, moved.found_people),
            (0, 0, 2)
        );
        // methods on features these observations lack: nothing filtered, all counted
        let exact = row("ceiling: exact masks");
        assert_eq!((exact.observations, exact.no_feature), (0, 4));
        // the per-observation table holds every observation of every run, labelled or not
        assert_eq!(got.observations.len(), 4 * (METHODS.len() - unfitted));
        let labelled = got
            .observations
            .iter()
            .filter(|o| o.label.is_some())
            .count();
        let with_feature = METHODS.iter().filter(|m| m.feature == F).count();
        assert_eq!(labelled, 4 * with_feature);
        // without a training split the fitted rows are left out
        let none = runs(&scored, &p, &Training::default()).expect("runs");
        // (every moved prior and the fitted nearest-neighbour threshold)
        assert_eq!(none.rows.len(), METHODS.len() - unfitted - 2);
    }

    const PAPER_NAME: &str = "paper (ADF)";
}
