//! Optimal bipartite assignment (linear sum assignment) for the three places the metrics need
//! one: CLEAR MOT's per-frame matching, the global identity matching of IDF1, and HOTA's
//! per-frame matching.
//!
//! The solver is `pathfinding::kuhn_munkres` (Hungarian algorithm, O(n³)) on integer weights.
//! Each wrapper turns its objective into integer weights, splits the problem into connected
//! components of the allowed pairs (a component of one pair needs no solver, and the sum of
//! per-component optima is the global optimum), and returns only allowed pairs, sorted by row.
//!
//! Floating costs are quantised to 2⁻ᴮ of their range with B = 40 bits for all but enormous
//! problems (fewer bits only beyond 2¹⁰ pairs a side, so that sums stay inside `i64`). Two
//! assignments whose total costs differ by less than that are treated as tied, and ties are
//! broken by the solver's order, not scipy's.

use pathfinding::kuhn_munkres::kuhn_munkres;
use pathfinding::matrix::Matrix;

/// Bits of resolution for quantised costs and scores, before the overflow guard.
const QUANT_BITS_MAX: u32 = 40;

/// Pairs `(row, col)` that maximise first the **number** of allowed pairs and then minimise
/// their **total cost**; `cost(row, col)` is NaN or infinite where a pair is forbidden.
///
/// This is what py-motmetrics gets from scipy's `linear_sum_assignment` after replacing
/// forbidden entries with a cost larger than any feasible alternative (`lap.add_expensive_edges`):
/// one more pair always beats any saving in distance.
pub fn min_cost_max_pairs(
    rows: usize,
    cols: usize,
    cost: impl Fn(usize, usize) -> f64,
) -> Vec<(usize, usize)> {
    let mut allowed = Vec::new();
    for r in 0..rows {
        for c in 0..cols {
            let x = cost(r, c);
            if x.is_finite() {
                allowed.push((r, c, x));
            }
        }
    }
    Assigner::default()
        .min_cost_max_pairs(rows, cols, &allowed)
        .to_vec()
}

/// Buffers for solving many small assignments in a row (CLEAR MOT's one per frame) without
/// allocating for each; the answers are those of the free functions.
#[derive(Debug, Default)]
pub struct Assigner {
    edges: Vec<(usize, usize, i64)>,
    keys: Vec<usize>,
    parent: Vec<usize>,
    by_root: Vec<(usize, usize)>,
    component: Vec<(usize, usize, i64)>,
    out: Vec<(usize, usize)>,
}

impl Assigner {
    /// [`min_cost_max_pairs`] over the allowed pairs `(row, col, cost)` (every cost finite),
    /// listed by row, then column.
    pub fn min_cost_max_pairs(
        &mut self,
        rows: usize,
        cols: usize,
        allowed: &[(usize, usize, f64)],
    ) -> &[(usize, usize)] {
        self.out.clear();
        if allowed.is_empty() {
            return &self.out;
        }
        let (lo, hi) = allowed.iter().fold(
            (f64::INFINITY, f64::NEG_INFINITY),
            |(lo, hi), &(_, _, x)| (lo.min(x), hi.max(x)),
        );
        let size = side_size_with(allowed, &mut self.keys);
        let bits = quant_bits(size);
        let range = hi - lo;
        let scale = if range > 0.0 {
            (1u64 << bits) as f64 / range
        } else {
            0.0
        };
        let max_q = 1i64 << bits;
        // Weight = K − quantised cost with K > size · max cost: a matching with one more pair
        // always weighs more, and among matchings of one size the cheapest weighs most.
        let k = size as i64 * max_q + 1;
        self.edges.clear();
        self.edges.extend(allowed.iter().map(|&(r, c, x)| {
            let q = (((x - lo) * scale).round() as i64).clamp(0, max_q);
            (r, c, k - q)
        }));
        self.max_weight_pairs(rows, cols);
        &self.out
    }

    /// Maximum-weight matching over `self.edges` (weights > 0), solved per connected
    /// component, into `self.out` sorted by row.
    fn max_weight_pairs(&mut self, rows: usize, cols: usize) {
        self.out.clear();
        if self.edges.is_empty() {
            return;
        }
        // Union-find over rows (0..rows) and columns (rows..rows + cols).
        let parent = &mut self.parent;
        parent.clear();
        parent.extend(0..rows + cols);
        fn find(parent: &mut [usize], mut x: usize) -> usize {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        }
        for &(r, c, _) in &self.edges {
            let a = find(parent, r);
            let b = find(parent, rows + c);
            if a != b {
                parent[a] = b;
            }
        }
        // Edges grouped by component, each group in edge order.
        self.by_root.clear();
        for (k, e) in self.edges.iter().enumerate() {
            self.by_root.push((find(parent, e.0), k));
        }
        self.by_root.sort_unstable();
        for group in self.by_root.chunk_by(|a, b| a.0 == b.0) {
            if let [(_, k)] = group {
                let (r, c, _) = self.edges[*k];
                self.out.push((r, c));
                continue;
            }
            self.component.clear();
            self.component
                .extend(group.iter().map(|&(_, k)| self.edges[k]));
            solve_component(&self.component, &mut self.out);
        }
        self.out.sort_unstable();
    }
}

/// Pairs `(row, col)` maximising the total of `score(row, col)`; pairs scoring zero or less
/// (or NaN) are never returned. HOTA's per-frame matching (TrackEval maximises the sum of
/// alignment × similarity with scipy).
pub fn max_score_pairs(
    rows: usize,
    cols: usize,
    score: impl Fn(usize, usize) -> f64,
) -> Vec<(usize, usize)> {
    let mut positive = Vec::new();
    let mut hi = 0.0f64;
    for r in 0..rows {
        for c in 0..cols {
            let x = score(r, c);
            if x > 0.0 && x.is_finite() {
                hi = hi.max(x);
                positive.push((r, c, x));
            }
        }
    }
    if positive.is_empty() {
        return Vec::new();
    }
    let bits = quant_bits(side_size(&positive));
    let scale = (1u64 << bits) as f64 / hi;
    let edges: Vec<(usize, usize, i64)> = positive
        .into_iter()
        .map(|(r, c, x)| (r, c, ((x * scale).round() as i64).max(1)))
        .collect();
    max_weight_pairs(rows, cols, &edges)
}

/// Pairs maximising the total of positive integer weights `(row, col, weight)`: IDF1's
/// global matching, where the weight of a trajectory pair is the number of frames in which
/// the two are close enough to match. Exact (no quantisation).
pub fn max_count_pairs(
    rows: usize,
    cols: usize,
    edges: &[(usize, usize, u64)],
) -> Vec<(usize, usize)> {
    let edges: Vec<(usize, usize, i64)> = edges
        .iter()
        .filter(|e| e.2 > 0)
        .map(|&(r, c, w)| (r, c, i64::try_from(w).unwrap_or(i64::MAX / (1 << 24))))
        .collect();
    max_weight_pairs(rows, cols, &edges)
}

/// The number of distinct rows or columns that have an edge, whichever is smaller: an upper
/// bound on the number of pairs in any matching.
fn side_size<T>(edges: &[(usize, usize, T)]) -> usize {
    side_size_with(edges, &mut Vec::new())
}

/// [`side_size`] with a caller's buffer.
fn side_size_with<T>(edges: &[(usize, usize, T)], keys: &mut Vec<usize>) -> usize {
    let mut distinct = |key: fn(&(usize, usize, T)) -> usize| {
        keys.clear();
        keys.extend(edges.iter().map(key));
        keys.sort_unstable();
        keys.dedup();
        keys.len()
    };
    let rs = distinct(|e| e.0);
    let cs = distinct(|e| e.1);
    rs.min(cs).max(1)
}

/// Bits of cost resolution such that `size² · 2^bits` stays well inside `i64`.
fn quant_bits(size: usize) -> u32 {
    let size_bits = usize::BITS - size.leading_zeros();
    QUANT_BITS_MAX
        .min(61u32.saturating_sub(2 * size_bits))
        .max(1)
}

/// Maximum-weight matching over the given edges (weights > 0), solved per connected
/// component. Returns pairs sorted by row.
fn max_weight_pairs(
    rows: usize,
    cols: usize,
    edges: &[(usize, usize, i64)],
) -> Vec<(usize, usize)> {
    let mut a = Assigner {
        edges: edges.to_vec(),
        ..Assigner::default()
    };
    a.max_weight_pairs(rows, cols);
    a.out
}

/// One connected component, dense, through `kuhn_munkres` (which wants rows ≤ columns).
fn solve_component(edges: &[(usize, usize, i64)], out: &mut Vec<(usize, usize)>) {
    let mut rs: Vec<usize> = edges.iter().map(|e| e.0).collect();
    let mut cs: Vec<usize> = edges.iter().map(|e| e.1).collect();
    rs.sort_unstable();
    rs.dedup();
    cs.sort_unstable();
    cs.dedup();
    let transpose = rs.len() > cs.len();
    let (n_small, n_large) = if transpose {
        (cs.len(), rs.len())
    } else {
        (rs.len(), cs.len())
    };
    let mut weights = Matrix::new(n_small, n_large, 0i64);
    let mut is_edge = vec![false; n_small * n_large];
    for &(r, c, w) in edges {
        let (Ok(ri), Ok(ci)) = (rs.binary_search(&r), cs.binary_search(&c)) else {
            continue;
        };
        let (a, b) = if transpose { (ci, ri) } else { (ri, ci) };
        weights[(a, b)] = weights[(a, b)].max(w);
        is_edge[a * n_large + b] = true;
    }
    let (_, assignment) = kuhn_munkres(&weights);
    for (a, &b) in assignment.iter().enumerate() {
        if !is_edge[a * n_large + b] {
            continue;
        }
        let (ri, ci) = if transpose { (b, a) } else { (a, b) };
        out.push((rs[ri], cs[ci]));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn min_cost(m: &[&[f64]]) -> Vec<(usize, usize)> {
        let cols = m.first().map_or(0, |r| r.len());
        min_cost_max_pairs(m.len(), cols, |r, c| m[r][c])
    }

    const X: f64 = f64::NAN;

    #[test]
    fn picks_the_cheapest_full_assignment() {
        assert_eq!(min_cost(&[&[1.0, 0.5], &[0.3, 1.0]]), vec![(0, 1), (1, 0)]);
        assert_eq!(min_cost(&[&[0.1, 0.2], &[0.2, 0.1]]), vec![(0, 0), (1, 1)]);
    }

    #[test]
    fn more_pairs_beat_a_cheaper_single_pair() {
        // (0,0) alone costs 0.1; (0,1)+(1,0) cost 0.9 but match two objects: motmetrics
        // (scipy with expensive forbidden edges) takes the two.
        assert_eq!(min_cost(&[&[0.1, 0.45], &[0.45, X]]), vec![(0, 1), (1, 0)]);
    }

    #[test]
    fn forbidden_pairs_are_never_returned() {
        assert_eq!(min_cost(&[&[X, X], &[X, X]]), vec![]);
        assert_eq!(min_cost(&[&[X, 0.3], &[X, 0.2]]), vec![(1, 1)]);
        assert_eq!(min_cost(&[&[f64::INFINITY, 0.3]]), vec![(0, 1)]);
    }

    #[test]
    fn rectangular_both_ways() {
        assert_eq!(min_cost(&[&[0.4, 0.1, 0.3]]), vec![(0, 1)]);
        assert_eq!(min_cost(&[&[0.4], &[0.1], &[0.3]]), vec![(1, 0)]);
        assert_eq!(
            min_cost(&[&[0.9, 0.1, 0.8], &[0.1, 0.2, 0.9]]),
            vec![(0, 1), (1, 0)]
        );
    }

    #[test]
    fn equal_costs_still_give_a_full_assignment() {
        assert_eq!(min_cost(&[&[0.5, 0.5], &[0.5, 0.5]]).len(), 2);
        assert_eq!(min_cost(&[&[0.0, 0.0], &[0.0, 0.0]]).len(), 2);
    }

    #[test]
    fn separate_components_are_solved_separately() {
        // Two 2x2 blocks, each with its own optimum, plus an isolated pair.
        let m: &[&[f64]] = &[
            &[0.1, 0.2, X, X, X],
            &[0.2, 0.9, X, X, X],
            &[X, X, 0.7, 0.1, X],
            &[X, X, 0.1, 0.7, X],
            &[X, X, X, X, 0.3],
        ];
        assert_eq!(min_cost(m), vec![(0, 1), (1, 0), (2, 3), (3, 2), (4, 4)]);
    }

    #[test]
    fn brute_force_agrees_on_small_matrices() {
        // Deterministic xorshift: all 3x3 and 3x4 cost matrices with some forbidden pairs.
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for case in 0..500 {
            let (n, m) = if case % 2 == 0 { (3, 3) } else { (3, 4) };
            let c: Vec<f64> = (0..n * m)
                .map(|_| {
                    let v = next();
                    if v % 4 == 0 {
                        X
                    } else {
                        (v >> 11) as f64 / (1u64 << 53) as f64
                    }
                })
                .collect();
            let got = min_cost_max_pairs(n, m, |r, k| c[r * m + k]);
            let got_key = (
                got.len(),
                got.iter().map(|&(r, k)| c[r * m + k]).sum::<f64>(),
            );
            let best = brute(n, m, &c);
            assert_eq!(got_key.0, best.0, "case {case}: {c:?}");
            assert!((got_key.1 - best.1).abs() < 1e-9, "case {case}: {c:?}");
        }
    }

    /// (most pairs, least cost among those) by trying every injective row → column map.
    fn brute(n: usize, m: usize, c: &[f64]) -> (usize, f64) {
        fn go(
            r: usize,
            n: usize,
            m: usize,
            c: &[f64],
            used: &mut Vec<bool>,
            acc: (usize, f64),
            best: &mut (usize, f64),
        ) {
            if r == n {
                if acc.0 > best.0 || (acc.0 == best.0 && acc.1 < best.1) {
                    *best = acc;
                }
                return;
            }
            go(r + 1, n, m, c, used, acc, best);
            for k in 0..m {
                if !used[k] && c[r * m + k].is_finite() {
                    used[k] = true;
                    go(
                        r + 1,
                        n,
                        m,
                        c,
                        used,
                        (acc.0 + 1, acc.1 + c[r * m + k]),
                        best,
                    );
                    used[k] = false;
                }
            }
        }
        let mut best = (0, f64::INFINITY);
        go(0, n, m, c, &mut vec![false; m], (0, 0.0), &mut best);
        if best.0 == 0 {
            best.1 = 0.0;
        }
        best
    }

    #[test]
    fn max_count_takes_the_heaviest_matching() {
        // 3 + 3 beats 5 alone.
        let e = [(0, 0, 5), (0, 1, 3), (1, 0, 3)];
        assert_eq!(max_count_pairs(2, 2, &e), vec![(0, 1), (1, 0)]);
        assert_eq!(max_count_pairs(2, 2, &[]), vec![]);
        assert_eq!(max_count_pairs(1, 3, &[(0, 2, 1)]), vec![(0, 2)]);
    }

    #[test]
    fn max_score_ignores_zero_scores() {
        let s: &[&[f64]] = &[&[0.0, 0.6], &[0.5, 0.7]];
        assert_eq!(max_score_pairs(2, 2, |r, c| s[r][c]), vec![(0, 1), (1, 0)]);
        assert_eq!(max_score_pairs(2, 2, |_, _| 0.0), vec![]);
    }

    #[test]
    fn quantisation_keeps_sums_inside_i64() {
        for size in [1usize, 2, 30, 1000, 1 << 12, 1 << 20] {
            let bits = quant_bits(size);
            let total = (size as i128) * ((size as i128) * (1i128 << bits) + 1);
            assert!(total < i64::MAX as i128 / 4, "size {size}, bits {bits}");
        }
    }
}
