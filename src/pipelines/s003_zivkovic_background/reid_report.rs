//! Re-identification, the report (seed 003 §IV–V): the cached per-frame features grouped
//! into local tracks — one observation each, the feature averaged over the track's frames as
//! in the paper, entered/left times as d_k — then each clip filtered online in order of the
//! tracks' ends by `track::reid` and scored by `eval::reid`, on ground-truth local tracks and
//! on the system's own, beside baselines in the same run. Tables `reid` and `reid_ttests`.

use std::collections::BTreeMap;

use super::params::{ClipParams, Params, ReidParams};
use super::reid::{FRAMES_TABLE, ReidFrameRow};
use crate::eval::reid::{retrieval, score};
use crate::eval::stats;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products};
use crate::table_row;
use crate::track::reid::{Prior, ReidFilter, Span, Terms};

/// One local track as an observation y_k = {o_k, d_k}.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Observation {
    /// The track id (system) or person id (truth) it came from.
    pub id: i64,
    /// The person it shows (system tracks: the most frequent match; `None`: no person).
    pub truth: Option<i64>,
    pub span: Span,
    pub frames: usize,
    pub feature: [f64; 9],
    pub raw: [f64; 9],
}

/// Local tracks of `source` from the per-frame rows: a person's (or track's) frames split
/// where it is unseen for more than `max_gap_s`; tracks shorter than `min_frames` dropped.
/// Ordered by when they ended (the filter's order), then start and id.
pub(super) fn observations(
    rows: &[ReidFrameRow],
    source: &str,
    p: &ReidParams,
) -> Vec<Observation> {
    let mut by_id: BTreeMap<i64, Vec<&ReidFrameRow>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.source == source) {
        by_id.entry(r.id).or_default().push(r);
    }
    let mut out = Vec::new();
    for (id, mut frames) in by_id {
        frames.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        let mut start = 0;
        for i in 1..=frames.len() {
            let split = i == frames.len() || frames[i].t_s - frames[i - 1].t_s > p.max_gap_s;
            if split {
                let piece = &frames[start..i];
                if piece.len() >= p.min_frames {
                    out.push(observation(id, piece));
                }
                start = i;
            }
        }
    }
    out.sort_by(|a, b| {
        (a.span.leave, a.span.enter, a.id)
            .partial_cmp(&(b.span.leave, b.span.enter, b.id))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    out
}

fn observation(id: i64, piece: &[&ReidFrameRow]) -> Observation {
    let n = piece.len() as f64;
    let mean = |raw: bool| -> [f64; 9] {
        let mut m = [0.0; 9];
        for r in piece {
            for (acc, v) in m.iter_mut().zip(r.feature(raw)) {
                *acc += v / n;
            }
        }
        m
    };
    let mut votes: BTreeMap<Option<i64>, usize> = BTreeMap::new();
    for r in piece {
        *votes.entry(r.truth_id).or_default() += 1;
    }
    // truth rows carry no truth_id: the person is the id itself
    let truth = if piece.iter().all(|r| r.source == "truth") {
        Some(id)
    } else {
        votes
            .iter()
            .max_by_key(|(k, c)| (**c, std::cmp::Reverse(**k)))
            .and_then(|(k, _)| *k)
    };
    Observation {
        id,
        truth,
        span: Span {
            enter: piece[0].t_s,
            leave: piece[piece.len() - 1].t_s,
        },
        frames: piece.len(),
        feature: mean(false),
        raw: mean(true),
    }
}

/// The methods compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Method {
    /// The paper's model: normalised colour, spatio-temporal term, ADF.
    Paper,
    NoSpatioTemporal,
    NoNormalisation,
    /// Nearest person mean within `nn_threshold`, not overlapping in time, else new.
    Nearest,
}

impl Method {
    const ALL: [Method; 4] = [
        Method::Paper,
        Method::NoSpatioTemporal,
        Method::NoNormalisation,
        Method::Nearest,
    ];

    fn name(self) -> &'static str {
        match self {
            Method::Paper => "paper (ADF)",
            Method::NoSpatioTemporal => "without spatio-temporal term",
            Method::NoNormalisation => "without colour normalisation",
            Method::Nearest => "nearest neighbour",
        }
    }
}

/// The label each method gives each observation (in order).
pub(super) fn labels(
    obs: &[&Observation],
    m: Method,
    p: &ReidParams,
) -> anyhow::Result<Vec<usize>> {
    if m == Method::Nearest {
        return Ok(nearest(obs, p.nn_threshold));
    }
    let terms = Terms {
        appearance: true,
        spatio_temporal: m != Method::NoSpatioTemporal,
    };
    let mut filter = ReidFilter::new(&Prior::paper(9), terms);
    let mut out = Vec::with_capacity(obs.len());
    for o in obs {
        let x = if m == Method::NoNormalisation {
            &o.raw
        } else {
            &o.feature
        };
        out.push(filter.observe(x, o.span)?.label);
    }
    Ok(out)
}

/// The baseline: each observation joins the person whose mean feature is nearest (Euclidean,
/// normalised feature) if closer than `threshold` and their last track ended before it
/// started; else it is a new person.
fn nearest(obs: &[&Observation], threshold: f64) -> Vec<usize> {
    // (sum of features, count, last leave time)
    let mut people: Vec<([f64; 9], f64, f64)> = Vec::new();
    let mut out = Vec::with_capacity(obs.len());
    for o in obs {
        let best = people
            .iter()
            .enumerate()
            .filter(|(_, (_, _, leave))| o.span.enter > *leave)
            .map(|(i, (sum, n, _))| {
                let d: f64 = (0..9).map(|j| (sum[j] / n - o.feature[j]).powi(2)).sum();
                (i, d.sqrt())
            })
            .filter(|(_, d)| *d < threshold)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let i = match best {
            Some((i, _)) => i,
            None => {
                people.push(([0.0; 9], 0.0, f64::NEG_INFINITY));
                people.len() - 1
            }
        };
        let person = &mut people[i];
        for j in 0..9 {
            person.0[j] += o.feature[j];
        }
        person.1 += 1.0;
        person.2 = person.2.max(o.span.leave);
        out.push(i + 1);
    }
    out
}

table_row! {
    /// A row of the `reid` table.
    #[derive(Debug, Clone, PartialEq)]
    struct ReidRow {
        dataset: String,
        session: String,
        clip: String,
        source: String,
        method: String,
        observations: i64,
        no_person: i64,
        true_people: i64,
        found_people: i64,
        people_error: i64,
        misidentified: i64,
        misidentified_pct: f64,
        pair_precision: f64,
        pair_recall: f64,
        pair_f1: f64,
        adjusted_rand: f64,
    }
}

table_row! {
    /// A row of the `reid_ttests` table.
    #[derive(Debug, Clone, PartialEq)]
    struct ReidTestRow {
        source: String,
        baseline: String,
        runs: i64,
        paper_misidentified_pct: f64,
        baseline_misidentified_pct: f64,
        t: Option<f64>,
        p_two_sided: Option<f64>,
    }
}

table_row! {
    /// A row of the `reid_retrieval` table.
    #[derive(Debug, Clone, PartialEq)]
    struct RetrievalRow {
        dataset: String,
        session: String,
        clip: String,
        source: String,
        feature: String,
        queries: i64,
        rank1: f64,
        map: f64,
    }
}

/// Rank-1 / mAP of a clip's scored observations, normalised and raw features.
fn retrieval_rows(head: [&str; 4], obs: &[&Observation]) -> Vec<RetrievalRow> {
    let scored: Vec<&&Observation> = obs.iter().filter(|o| o.truth.is_some()).collect();
    let truth: Vec<Option<i64>> = scored.iter().map(|o| o.truth).collect();
    [("ln grey-world", false), ("raw RGB", true)]
        .into_iter()
        .map(|(name, raw)| {
            let f: Vec<Vec<f64>> = scored
                .iter()
                .map(|o| {
                    if raw {
                        o.raw.to_vec()
                    } else {
                        o.feature.to_vec()
                    }
                })
                .collect();
            let r = retrieval(&f, &truth);
            RetrievalRow {
                dataset: head[0].into(),
                session: head[1].into(),
                clip: head[2].into(),
                source: head[3].into(),
                feature: name.into(),
                queries: r.queries as i64,
                rank1: r.rank1,
                map: r.map,
            }
        })
        .collect()
}

pub(super) fn in_clip(o: &Observation, c: &ClipParams) -> bool {
    c.until_s.is_none_or(|t| o.span.leave <= t)
}

/// Every (session, clip, source, method) run, and the clips' retrieval scores.
fn runs(ctx: &Aggregate, p: &ReidParams) -> anyhow::Result<(Vec<ReidRow>, Vec<RetrievalRow>)> {
    let mut rows = Vec::new();
    let mut retrieval = Vec::new();
    for (info, tables) in ctx.sessions {
        let Some(df) = tables.get(FRAMES_TABLE) else {
            continue;
        };
        let frames = ReidFrameRow::read(df)?;
        for source in ["truth", "system"] {
            let all = observations(&frames, source, p);
            for clip in &p.clips {
                let obs: Vec<&Observation> = all.iter().filter(|o| in_clip(o, clip)).collect();
                retrieval.extend(retrieval_rows(
                    [&info.dataset, &info.name, &clip.name, source],
                    &obs,
                ));
                for m in Method::ALL {
                    let got = labels(&obs, m, p)?;
                    let (truth, est): (Vec<i64>, Vec<usize>) = obs
                        .iter()
                        .zip(&got)
                        .filter_map(|(o, l)| o.truth.map(|t| (t, *l)))
                        .unzip();
                    let s = score(&truth, &est);
                    rows.push(ReidRow {
                        dataset: info.dataset.clone(),
                        session: info.name.clone(),
                        clip: clip.name.clone(),
                        source: source.into(),
                        method: m.name().into(),
                        observations: obs.len() as i64,
                        no_person: (obs.len() - s.observations) as i64,
                        true_people: s.true_people as i64,
                        found_people: s.found_people as i64,
                        people_error: s.people_error,
                        misidentified: s.misidentified as i64,
                        misidentified_pct: 100.0 * s.misidentified as f64
                            / s.observations.max(1) as f64,
                        pair_precision: s.pair_precision,
                        pair_recall: s.pair_recall,
                        pair_f1: s.pair_f1,
                        adjusted_rand: s.adjusted_rand,
                    });
                }
            }
        }
    }
    Ok((rows, retrieval))
}

/// Paired t-tests of the mis-identified percentage: the paper's model against each baseline
/// over every (session, clip) run of a source.
fn ttests(rows: &[ReidRow], level: f64) -> Vec<ReidTestRow> {
    let mut out = Vec::new();
    for source in ["truth", "system"] {
        let of = |m: Method| -> Vec<f64> {
            rows.iter()
                .filter(|r| r.source == source && r.method == m.name())
                .map(|r| r.misidentified_pct)
                .collect()
        };
        let paper = of(Method::Paper);
        for m in &Method::ALL[1..] {
            let other = of(*m);
            let test = stats::paired_t(&paper, &other, level).ok();
            let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
            out.push(ReidTestRow {
                source: source.into(),
                baseline: m.name().into(),
                runs: paper.len() as i64,
                paper_misidentified_pct: mean(&paper),
                baseline_misidentified_pct: mean(&other),
                t: test.as_ref().map(|t| t.t).filter(|t| t.is_finite()),
                p_two_sided: test
                    .as_ref()
                    .map(|t| t.p_two_sided)
                    .filter(|p| p.is_finite()),
            });
        }
    }
    out
}

pub(super) fn products(ctx: &Aggregate, p: &Params, products: &mut Products) -> anyhow::Result<()> {
    let r = &p.reid;
    let (rows, retrieval) = runs(ctx, r)?;
    if rows.is_empty() {
        return Ok(());
    }
    for row in rows.iter().filter(|x| x.method == Method::Paper.name()) {
        products.summary.push(format!(
            "{}/{} re-identification, {} ({} tracks): {} of {} observations mis-identified, {} people found for {}.",
            row.session, row.clip, row.source, row.observations, row.misidentified,
            row.observations - row.no_person, row.found_people, row.true_people
        ));
    }
    let clips: Vec<String> = r
        .clips
        .iter()
        .map(|c| match c.until_s {
            Some(t) => format!("{} = tracks ended by {t} s", c.name),
            None => format!("{} = the whole session", c.name),
        })
        .collect();
    products.tables.push(
        Table::new("reid", "Re-identification across local tracks (Zajdel et al.): the paper's model beside baselines, on ground-truth and on the system's own local tracks", ReidRow::frame(&rows)?)
            .with_precision("misidentified_pct", 1)
            .with_precision("pair_precision", 3)
            .with_precision("pair_recall", 3)
            .with_precision("pair_f1", 3)
            .with_precision("adjusted_rand", 3)
            .with_note("Paper (two real clips): clip 1, two places lit alike — every person identified correctly (0 errors); clip 2, across strongly different light — one of five people wrongly identified as a new person.")
            .with_note(format!("Clips: {}. Observations are local tracks (gap > {} s splits a track, fewer than {} frames dropped), filtered in order of their end; `truth` = ground-truth boxes with visibility ≥ {}, `system` = the local tracker's tracks, each scored as the person it overlaps most (IoU ≥ local_eval.min_iou; `no_person` = tracks on no person, filtered but not scored).", clips.join("; "), r.max_gap_s, r.min_frames, r.min_visibility))
            .with_note(format!("Prior as printed: a₀ = 0, κ₀ = 100, η₀ = 9, C₀ = 10⁻³·I; P_δ = 0 when a track starts before the person's previous one ended. Nearest neighbour: threshold {} on the normalised feature (chosen a priori, not tuned), with the same no-overlap rule. misidentified = observations not on their person under the best one-to-one label mapping; people_error = found − true.", r.nn_threshold)),
    );
    products.tables.push(
        Table::new("reid_retrieval", "Re-identification as retrieval: rank-1 and mAP, each scored local track querying the clip's others by feature distance", RetrievalRow::frame(&retrieval)?)
            .with_precision("rank1", 3)
            .with_precision("map", 3)
            .with_note("Euclidean distance between the tracks' mean 9-D features (ln grey-world, or raw RGB / 255); queries = tracks whose person has another track in the clip. Not in the paper (our addition, the usual re-identification measure)."),
    );
    products.tables.push(
        Table::new("reid_ttests", "Re-identification: paired t-tests of the mis-identified percentage, the paper's model against each baseline", ReidTestRow::frame(&ttests(&rows, r.level))?)
            .with_precision("paper_misidentified_pct", 1)
            .with_precision("baseline_misidentified_pct", 1)
            .with_precision("t", 3)
            .with_precision("p_two_sided", 4)
            .with_note("Over every (session, clip) run of each source; t and p are empty when there are fewer than two runs or no variation."),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t_s: f64, id: i64, f: f64, truth_id: Option<i64>, source: &str) -> ReidFrameRow {
        let mut feature = [0.0; 9];
        feature[0] = f;
        ReidFrameRow::new(
            (0, t_s, source, id, truth_id),
            feature,
            feature.map(|v| v / 2.0),
        )
    }

    #[test]
    fn tracks_split_at_gaps_average_their_features_and_vote_their_person() {
        let p = ReidParams {
            max_gap_s: 1.0,
            min_frames: 2,
            ..ReidParams::default()
        };
        let rows = vec![
            row(0.0, 7, 1.0, Some(1), "system"),
            row(0.5, 7, 3.0, Some(1), "system"),
            row(1.0, 7, 2.0, Some(2), "system"),
            // 2.5 s gap: a new track, of one frame only → dropped
            row(3.5, 7, 9.0, None, "system"),
            row(0.2, 3, 1.0, None, "truth"),
            row(0.4, 3, 1.0, None, "truth"),
        ];
        let sys = observations(&rows, "system", &p);
        assert_eq!(sys.len(), 1);
        assert_eq!(sys[0].truth, Some(1), "two of three frames on person 1");
        assert_eq!(
            (sys[0].span.enter, sys[0].span.leave, sys[0].frames),
            (0.0, 1.0, 3)
        );
        assert_eq!(sys[0].feature[0], 2.0);
        assert_eq!(sys[0].raw[0], 1.0);
        let truth = observations(&rows, "truth", &p);
        assert_eq!(truth[0].truth, Some(3));
    }

    #[test]
    fn two_people_seen_twice_each_are_re_identified_by_the_papers_model() {
        let p = ReidParams::default();
        // two looks that differ in every region and channel
        let look = |person: i64| -> [f64; 9] {
            if person == 1 {
                [0.5, -0.5, 0.1, -0.5, 0.5, 0.0, 0.15, 0.0, -0.15]
            } else {
                [-0.3, 0.2, 0.4, 0.1, -0.4, 0.3, -0.2, 0.5, 0.1]
            }
        };
        let mut rows = Vec::new();
        // person 1 at 0–2 s and 10–12 s, person 2 at 5–7 s and 15–17 s, 10 frames each
        for (person, start) in [(1, 0.0), (2, 5.0), (1, 10.0), (2, 15.0)] {
            for i in 0..10 {
                let t = start + 0.2 * f64::from(i);
                let jitter = 0.01 * f64::from(i % 3);
                let f = look(person).map(|v| v + jitter);
                rows.push(ReidFrameRow::new((0, t, "truth", person, None), f, f));
            }
        }
        let obs = observations(&rows, "truth", &p);
        assert_eq!(obs.len(), 4);
        let refs: Vec<&Observation> = obs.iter().collect();
        assert_eq!(
            labels(&refs, Method::Paper, &p).expect("labels"),
            [1, 2, 1, 2]
        );
        let truth: Vec<i64> = obs.iter().filter_map(|o| o.truth).collect();
        let s = score(&truth, &[1, 2, 1, 2]);
        assert_eq!((s.misidentified, s.people_error), (0, 0));
    }

    #[test]
    fn nearest_neighbour_joins_within_the_threshold_and_never_overlapping_tracks() {
        let o = |enter: f64, leave: f64, f: f64| Observation {
            id: 0,
            truth: None,
            span: Span { enter, leave },
            frames: 5,
            feature: [f, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            raw: [0.0; 9],
        };
        let obs = [
            o(0.0, 1.0, 0.0),
            o(2.0, 3.0, 0.05),
            o(2.5, 4.0, 0.0),
            o(5.0, 6.0, 1.0),
        ];
        let refs: Vec<&Observation> = obs.iter().collect();
        // the third overlaps the second (same person, mean 0.025): new; the fourth is far
        assert_eq!(nearest(&refs, 0.1), [1, 1, 2, 3]);
    }
}
