//! Re-identification scores: how well estimated identity labels of observations (local
//! tracks) agree with the true identities.
//!
//! - Seed 003's two measures: mis-identified observations (after the one-to-one mapping of
//!   labels to people that agrees most often, found exactly with `assign::max_count_pairs`)
//!   and the error in the number of distinct people; and its way of counting people (§V: "one
//!   out of five encountered persons was wrongly identified as a new individual"): people
//!   *wrongly new* — an observation of theirs got a label no person maps to, a new individual
//!   — and people *merged* — an observation of theirs got the label of another person.
//! - Pairwise precision / recall / F1 over all pairs of observations ("same person?").
//! - The adjusted Rand index (Hubert & Arabie 1985) from the contingency table.
//! - Retrieval: rank-1 and mean average precision, each observation querying all the others.
//!
//! Pure functions of the two label lists; the order of observations does not matter.

use std::collections::BTreeMap;

use crate::assign::max_count_pairs;

/// Scores of one labelling against the truth.
#[derive(Debug, Clone, PartialEq)]
pub struct ReidScores {
    pub observations: usize,
    /// Observations whose label does not map to their person (seed 003's identification
    /// error).
    pub misidentified: usize,
    pub true_people: usize,
    pub found_people: usize,
    /// found − true (the paper's error in the number of distinct people; signed).
    pub people_error: i64,
    /// People with an observation labelled as nobody's (a new individual).
    pub wrongly_new: usize,
    /// People with an observation labelled as another person.
    pub merged: usize,
    /// People with either (each counted once).
    pub people_wrong: usize,
    pub pair_precision: f64,
    pub pair_recall: f64,
    pub pair_f1: f64,
    pub adjusted_rand: f64,
}

/// The contingency table: counts of (truth, label) pairs, with dense indices.
fn contingency<T: Ord, L: Ord>(truth: &[T], labels: &[L]) -> (Vec<Vec<u64>>, usize, usize) {
    let mut ti = BTreeMap::new();
    let mut li = BTreeMap::new();
    for t in truth {
        let n = ti.len();
        ti.entry(t).or_insert(n);
    }
    for l in labels {
        let n = li.len();
        li.entry(l).or_insert(n);
    }
    let mut table = vec![vec![0u64; li.len()]; ti.len()];
    for (t, l) in truth.iter().zip(labels) {
        table[ti[t]][li[l]] += 1;
    }
    (table, ti.len(), li.len())
}

fn pairs(n: u64) -> f64 {
    (n * n.saturating_sub(1) / 2) as f64
}

/// Score `labels` (estimated) against `truth`, observation by observation. Panics never;
/// lists of different lengths are scored over their common prefix.
pub fn score<T: Ord, L: Ord>(truth: &[T], labels: &[L]) -> ReidScores {
    let n = truth.len().min(labels.len());
    let (truth, labels) = (&truth[..n], &labels[..n]);
    let (table, rows, cols) = contingency(truth, labels);
    let edges: Vec<(usize, usize, u64)> = table
        .iter()
        .enumerate()
        .flat_map(|(r, row)| {
            row.iter()
                .enumerate()
                .filter(|(_, c)| **c > 0)
                .map(move |(c, count)| (r, c, *count))
        })
        .collect();
    let pairs_found = max_count_pairs(rows, cols, &edges);
    let matched: u64 = pairs_found.iter().map(|&(r, c)| table[r][c]).sum();
    // person of each label under the mapping (None: a label no person maps to)
    let mut person_of = vec![None; cols];
    for &(r, c) in &pairs_found {
        person_of[c] = Some(r);
    }
    let (mut wrongly_new, mut merged, mut people_wrong) = (0, 0, 0);
    for (r, row) in table.iter().enumerate() {
        let off = |c: usize| row[c] > 0 && person_of[c] != Some(r);
        let new = (0..cols).any(|c| off(c) && person_of[c].is_none());
        let other = (0..cols).any(|c| off(c) && person_of[c].is_some());
        wrongly_new += usize::from(new);
        merged += usize::from(other);
        people_wrong += usize::from(new || other);
    }
    let same_both: f64 = table.iter().flatten().map(|&c| pairs(c)).sum();
    let same_truth: f64 = table.iter().map(|row| pairs(row.iter().sum())).sum();
    let same_label: f64 = (0..cols)
        .map(|c| pairs(table.iter().map(|row| row[c]).sum()))
        .sum();
    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 1.0 };
    let precision = ratio(same_both, same_label);
    let recall = ratio(same_both, same_truth);
    let f1 = if precision + recall > 0.0 {
        2.0 * precision * recall / (precision + recall)
    } else {
        0.0
    };
    let expected = same_truth * same_label / pairs(n as u64).max(1.0);
    let max_index = 0.5 * (same_truth + same_label);
    let adjusted_rand = if (max_index - expected).abs() < f64::EPSILON {
        1.0 // both are a single cluster or all singletons: identical partitions
    } else {
        (same_both - expected) / (max_index - expected)
    };
    ReidScores {
        observations: n,
        misidentified: n - matched as usize,
        true_people: rows,
        found_people: cols,
        people_error: cols as i64 - rows as i64,
        wrongly_new,
        merged,
        people_wrong,
        pair_precision: precision,
        pair_recall: recall,
        pair_f1: f1,
        adjusted_rand,
    }
}

/// Retrieval scores of a gallery: every observation queries all the others, ranked by
/// Euclidean distance of their features (ties in observation order).
#[derive(Debug, Clone, PartialEq)]
pub struct Retrieval {
    /// Queries with at least one other observation of the same person.
    pub queries: usize,
    /// Share of queries whose nearest other observation is the same person.
    pub rank1: f64,
    /// Mean over queries of the average precision of the ranking.
    pub map: f64,
}

/// Rank-1 and mAP of `features` (one per observation) against `truth`.
pub fn retrieval<T: PartialEq>(features: &[Vec<f64>], truth: &[T]) -> Retrieval {
    let n = features.len().min(truth.len());
    let (mut queries, mut hits, mut ap_sum) = (0usize, 0usize, 0.0);
    for q in 0..n {
        let positives = (0..n).filter(|&g| g != q && truth[g] == truth[q]).count();
        if positives == 0 {
            continue;
        }
        let mut ranked: Vec<(f64, usize)> = (0..n)
            .filter(|&g| g != q)
            .map(|g| {
                let d: f64 = features[q]
                    .iter()
                    .zip(&features[g])
                    .map(|(a, b)| (a - b).powi(2))
                    .sum();
                (d, g)
            })
            .collect();
        ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        queries += 1;
        hits += usize::from(truth[ranked[0].1] == truth[q]);
        let (mut found, mut ap) = (0usize, 0.0);
        for (rank, (_, g)) in ranked.iter().enumerate() {
            if truth[*g] == truth[q] {
                found += 1;
                ap += found as f64 / (rank + 1) as f64;
            }
        }
        ap_sum += ap / positives as f64;
    }
    let q = queries.max(1) as f64;
    Retrieval {
        queries,
        rank1: hits as f64 / q,
        map: ap_sum / q,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn retrieval_by_hand() {
        // 1-D features: a a' b b' c, where b' sits nearer to a than to b
        let f: Vec<Vec<f64>> = [0.0, 0.1, 5.0, 0.3, 9.0].iter().map(|v| vec![*v]).collect();
        let truth = ["a", "a", "b", "b", "c"];
        let r = retrieval(&f, &truth);
        // c has no partner: 4 queries. a → a' (hit, AP 1); a' → a (hit, AP 1);
        // b (5) → c 4.0, b' 4.7, a' 4.9, a 5.0: miss, b' at rank 2, AP 1/2;
        // b' (0.3) → a' 0.2, a 0.3, b 4.7: miss, AP 1/3
        assert_eq!(r.queries, 4);
        assert_eq!(r.rank1, 0.5);
        assert!((r.map - (2.0 + 0.5 + 1.0 / 3.0) / 4.0).abs() < 1e-15);
    }

    #[test]
    fn a_perfect_labelling_up_to_renaming() {
        let s = score(&[1, 1, 2, 3, 2], &["b", "b", "a", "c", "a"]);
        assert_eq!((s.misidentified, s.people_error), (0, 0));
        assert_eq!(
            (s.pair_precision, s.pair_recall, s.adjusted_rand),
            (1.0, 1.0, 1.0)
        );
    }

    #[test]
    fn one_person_wrongly_new_as_in_the_papers_second_clip() {
        // five people, one of them (4) seen twice but labelled new the second time
        let truth = [1, 2, 3, 4, 5, 4, 1];
        let labels = [1, 2, 3, 4, 5, 6, 1];
        let s = score(&truth, &labels);
        assert_eq!((s.misidentified, s.true_people, s.found_people), (1, 5, 6));
        assert_eq!(s.people_error, 1);
        assert_eq!((s.wrongly_new, s.merged, s.people_wrong), (1, 0, 1));
        // same-person pairs: (1,1) and (4,4); the labelling keeps (1,1) only
        assert_eq!((s.pair_precision, s.pair_recall), (1.0, 0.5));
        assert!((s.pair_f1 - 2.0 / 3.0).abs() < 1e-15);
        // scikit-learn 1.9.1: adjusted_rand_score(truth, labels)
        assert!((s.adjusted_rand - 0.6440677966101694).abs() < 1e-12);
    }

    #[test]
    fn people_merged_and_wrongly_new_counted_once_each() {
        // person 2's second look joins person 1; person 3's third look is a new label;
        // person 4 has one of each: 3 of 4 people wrong, one of them both ways
        let truth = [1, 1, 2, 2, 3, 3, 3, 4, 4, 4, 4];
        let labels = [1, 1, 2, 1, 3, 3, 5, 4, 4, 6, 3];
        let s = score(&truth, &labels);
        // the one best mapping: 1→1, 2→2, 3→3, 4→4; labels 5 and 6 are nobody's
        assert_eq!(s.misidentified, 4);
        assert_eq!((s.wrongly_new, s.merged, s.people_wrong), (2, 2, 3));
        assert_eq!(s.people_error, 2);
        // a perfect labelling has nobody wrong
        let p = score(&[1, 2, 1], &[7, 8, 7]);
        assert_eq!((p.wrongly_new, p.merged, p.people_wrong), (0, 0, 0));
    }

    #[test]
    fn adjusted_rand_index_against_scikit_learn() {
        // sklearn.metrics.adjusted_rand_score (scikit-learn 1.9.1) on the same lists
        let cases: [(&[i32], &[i32], f64); 3] = [
            (&[0, 0, 1, 1], &[0, 0, 1, 2], 0.5714285714285714),
            (&[0, 0, 1, 2], &[0, 0, 1, 1], 0.5714285714285714),
            (
                &[0, 0, 0, 1, 1, 1, 2, 2],
                &[0, 0, 1, 1, 2, 2, 2, 0],
                0.047619047619047616,
            ),
        ];
        for (truth, labels, want) in cases {
            let got = score(truth, labels).adjusted_rand;
            assert!(
                (got - want).abs() < 1e-12,
                "{truth:?} {labels:?}: {got} vs {want}"
            );
        }
    }
}
