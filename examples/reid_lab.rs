//! Development probe for re-identification (issue 31, round 6): the paper's filter
//! (`track::reid`) on observations given as CSV, to try a feature without running the
//! pipeline — with the printed prior and with the prior moved (`Prior::moved`) on the rows of
//! split `train` (their `across light` clip, i.e. the whole tour, as the pipeline fits it) —
//! printing each `score` session's mis-identified observations, people merged and wrongly new
//! per clip, and the totals.
//!
//! CSV, a header line then one observation per line:
//! `split,session,clip,order,truth,enter,leave,f1,…,f9` — split `train` or `score`; clip
//! `similar light` or `across light`; `order` the filter's order within (session, clip) (by
//! when the track ended, as `reid_features::observations`); `truth` the person; `enter` /
//! `leave` seconds; f1–f9 the 9-D feature. Written from a run's cached `reid_frames` tables.
//!
//! `cargo run --release --example reid_lab -- observations.csv`

use std::collections::BTreeMap;

use peopletrack::eval::reid::score;
use peopletrack::track::reid::{Prior, ReidFilter, Span, Terms};

type Obs = (String, f64, f64, i64, [f64; 9]);

fn main() -> anyhow::Result<()> {
    let path = std::env::args()
        .nth(1)
        .ok_or_else(|| anyhow::anyhow!("usage: reid_lab FILE"))?;
    let text = std::fs::read_to_string(&path)?;
    // (split, session, clip) -> observations in order
    let mut groups: BTreeMap<(String, String, String), Vec<(i64, Obs)>> = BTreeMap::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        anyhow::ensure!(
            c.len() == 16,
            "{path}:{}: {} fields, want 16 (split,session,clip,order,truth,enter,leave,f1..f9)",
            n + 1,
            c.len()
        );
        let f: Vec<f64> = c[7..16]
            .iter()
            .map(|v| v.parse())
            .collect::<Result<_, _>>()?;
        let o: Obs = (
            c[1].to_string(),
            c[5].parse()?,
            c[6].parse()?,
            c[4].parse()?,
            std::array::from_fn(|i| f[i]),
        );
        groups
            .entry((c[0].into(), c[1].into(), c[2].into()))
            .or_default()
            .push((c[3].parse()?, o));
    }
    let mut people: BTreeMap<(String, i64), Vec<Vec<f64>>> = BTreeMap::new();
    for ((split, _, clip), obs) in &groups {
        if split == "train" && clip == "across light" {
            for (_, o) in obs {
                people
                    .entry((o.0.clone(), o.3))
                    .or_default()
                    .push(o.4.to_vec());
            }
        }
    }
    let groups_train: Vec<Vec<Vec<f64>>> = people.into_values().collect();
    let moved = Prior::paper(9).moved(&groups_train);
    if let Some(m) = &moved {
        println!(
            "moved: kappa0 {:.3} c0 {:.5} within {:.4} between {:.4}",
            m.prior.kappa0, m.prior.c0, m.within_sd, m.between_sd
        );
    }
    let mut priors = vec![("printed", Prior::paper(9))];
    if let Some(m) = moved {
        priors.push(("moved", m.prior));
    }
    for (name, prior) in &priors {
        let mut totals: BTreeMap<String, (usize, usize, usize, usize, usize)> = BTreeMap::new();
        for ((split, session, clip), obs) in &groups {
            if split != "score" {
                continue;
            }
            let mut obs = obs.clone();
            obs.sort_by_key(|(k, _)| *k);
            let terms = Terms {
                appearance: true,
                spatio_temporal: true,
            };
            let mut filter = ReidFilter::new(prior, terms);
            let mut labels = Vec::new();
            for (_, o) in &obs {
                labels.push(
                    filter
                        .observe(
                            &o.4,
                            Span {
                                enter: o.1,
                                leave: o.2,
                            },
                        )?
                        .label,
                );
            }
            let truth: Vec<i64> = obs.iter().map(|(_, o)| o.3).collect();
            let s = score(&truth, &labels);
            println!(
                "{name:8} {session} {clip:14} obs {:2} mis {:2} merged {} new {}",
                s.observations, s.misidentified, s.merged, s.wrongly_new
            );
            let t = totals.entry(clip.clone()).or_default();
            t.0 += s.misidentified;
            t.1 += usize::from(s.misidentified == 0);
            t.2 += s.merged;
            t.3 += s.wrongly_new;
            t.4 += 1;
        }
        for (clip, t) in totals {
            println!(
                "== {name} {clip}: mis {} sessions without error {} of {} merged {} new {}",
                t.0, t.1, t.4, t.2, t.3
            );
        }
    }
    Ok(())
}
