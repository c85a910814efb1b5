//! Fragments of one upright person grouped into one blob before tracking.
//!
//! Background subtraction splits a person whose clothes resemble the background behind them:
//! on the `home_tour` scenes the shirt is often lost, leaving the head and the legs as two
//! blobs one above the other (each a false positive and the person a miss). An upright person
//! occupies one column of the image, so blobs that share most of a column and lie one above
//! the other with a gap no larger than a torso are taken as one person: two blobs are grouped
//! when their horizontal extents overlap by at least half the narrower one's width and the
//! rows between them are at most `group_gap` of the height of their union box (the torso,
//! shoulders to hips, is about 0.3 of the stature in anthropometric tables: a wholly lost
//! shirt leaves a gap of that size). Grouping is transitive (head, shirt and legs form one
//! blob) and repeated until no two groups qualify. The grouped blob has the fragments' summed
//! moments, the union of their boxes and the smallest of their labels; the label image is
//! rewritten so that its pixels carry that label (the fragments' pixels, never the gap's).
//!
//! Side by side blobs (two people walking together, or two legs) do not share a column and
//! stay apart; a person standing in front of another is usually one connected blob already.

use super::super::blobs::Blob;

/// Whether `a` and `b` are fragments of one upright person (see the module doc).
fn same_person(a: &Blob, b: &Blob, group_gap: f64) -> bool {
    let [ax0, ay0, ax1, ay1] = a.bbox.map(i64::from);
    let [bx0, by0, bx1, by1] = b.bbox.map(i64::from);
    let overlap = ax1.min(bx1) - ax0.max(bx0) + 1;
    let narrower = (ax1 - ax0 + 1).min(bx1 - bx0 + 1);
    if 2 * overlap < narrower {
        return false;
    }
    let gap = ay0.max(by0) - ay1.min(by1) - 1;
    let height = ay1.max(by1) - ay0.min(by0) + 1;
    gap as f64 <= group_gap * height as f64
}

/// Whether a blob is upright: the vertical variance of its pixels at least the horizontal
/// (a standing person; a passing car or a lying shadow is wider than tall).
pub(super) fn upright(b: &Blob) -> bool {
    b.moments
        .covariance()
        .is_some_and(|c| c[(1, 1)] >= c[(0, 0)])
}

fn merge(a: &Blob, b: &Blob) -> Blob {
    Blob {
        label: a.label.min(b.label),
        moments: a.moments.merged(&b.moments),
        bbox: [
            a.bbox[0].min(b.bbox[0]),
            a.bbox[1].min(b.bbox[1]),
            a.bbox[2].max(b.bbox[2]),
            a.bbox[3].max(b.bbox[3]),
        ],
    }
}

/// Group the fragments among `blobs` (in label order) and relabel `labels` (the label image
/// they came from) accordingly; returns the groups in order of their (smallest) label.
/// `group_gap` ≤ −1 disables grouping (no gap is that negative).
pub(super) fn group(blobs: Vec<Blob>, labels: &mut [u32], group_gap: f64) -> Vec<Blob> {
    let mut groups = blobs;
    // each original label's group label, to rewrite the image once at the end
    let mut renamed: Vec<(u32, u32)> = Vec::new();
    loop {
        let mut pair = None;
        'search: for i in 0..groups.len() {
            for j in i + 1..groups.len() {
                if same_person(&groups[i], &groups[j], group_gap) {
                    pair = Some((i, j));
                    break 'search;
                }
            }
        }
        let Some((i, j)) = pair else {
            break;
        };
        let (keep, gone) = if groups[i].label < groups[j].label {
            (groups[i].label, groups[j].label)
        } else {
            (groups[j].label, groups[i].label)
        };
        let merged = merge(&groups[i], &groups[j]);
        for r in &mut renamed {
            if r.1 == gone {
                r.1 = keep;
            }
        }
        renamed.push((gone, keep));
        groups[i] = merged;
        groups.remove(j);
    }
    groups.sort_by_key(|g| g.label);
    if !renamed.is_empty() {
        let max = renamed.iter().map(|r| r.0).max().unwrap_or(0) as usize;
        let mut to = vec![0u32; max + 1];
        for &(from, into) in &renamed {
            to[from as usize] = into;
        }
        for l in labels.iter_mut() {
            if let Some(&t) = to.get(*l as usize)
                && t != 0
            {
                *l = t;
            }
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::blobs::{self, Connectivity};

    /// Label a mask drawn as rectangles `[x0, y0, x1, y1]` (inclusive) on a `w`×`h` image.
    fn labelled(w: usize, h: usize, rects: &[[usize; 4]]) -> (Vec<Blob>, Vec<u32>, Vec<u8>) {
        let mut mask = vec![0u8; w * h];
        for r in rects {
            for y in r[1]..=r[3] {
                for x in r[0]..=r[2] {
                    mask[y * w + x] = 255;
                }
            }
        }
        let mut labels = vec![0u32; w * h];
        let b = blobs::label(&mask, w, h, Connectivity::Eight, 255, &mut labels).expect("label");
        (b, labels, mask)
    }

    #[test]
    fn a_person_split_at_the_shirt_is_one_blob_with_the_exact_union() {
        // head + shoulders rows 10–29, legs rows 45–89 (gap of 15 rows, the union 80 tall:
        // 15 ≤ 0.3·80), both in columns 40–55 / 42–53
        let (w, h) = (100, 100);
        let (b, mut labels, mask) = labelled(w, h, &[[42, 10, 53, 29], [40, 45, 55, 89]]);
        assert_eq!(b.len(), 2);
        let area = b[0].area() + b[1].area();
        let g = group(b.clone(), &mut labels, 0.3);
        assert_eq!(g.len(), 1);
        assert_eq!(g[0].bbox, [40, 10, 55, 89]);
        assert_eq!(g[0].area(), area);
        assert_eq!(g[0].moments, b[0].moments.merged(&b[1].moments));
        assert_eq!(g[0].label, 1);
        // every fragment pixel carries the group's label, nothing else does
        for (l, m) in labels.iter().zip(&mask) {
            assert_eq!(*l, if *m == 255 { 1 } else { 0 });
        }
    }

    #[test]
    fn upright_blobs_are_taller_than_wide_by_their_moments() {
        // a 10×30 person, a 30×10 car, a 20×20 square (equal variances: upright)
        let (b, _, _) = labelled(
            100,
            100,
            &[[5, 5, 14, 34], [40, 5, 69, 14], [40, 50, 59, 69]],
        );
        let up: Vec<bool> = b.iter().map(upright).collect();
        assert_eq!(up, vec![true, false, true]);
    }

    #[test]
    fn the_gap_limit_is_a_share_of_the_union_height() {
        // union 80 rows tall: a 24-row gap is exactly 0.3·80, a 25-row gap (union 81) is not
        let (w, h) = (100, 120);
        let (b, mut labels, _) = labelled(w, h, &[[40, 10, 55, 29], [40, 54, 55, 89]]);
        assert_eq!(group(b, &mut labels, 0.3).len(), 1);
        let (b, mut labels, _) = labelled(w, h, &[[40, 10, 55, 29], [40, 55, 55, 90]]);
        assert_eq!(group(b, &mut labels, 0.3).len(), 2);
    }

    #[test]
    fn side_by_side_blobs_and_disabled_grouping_stay_apart() {
        // two people side by side (columns 10–25 and 30–45, same rows): no shared column
        let (w, h) = (100, 100);
        let (b, mut labels, _) = labelled(w, h, &[[10, 10, 25, 80], [30, 10, 45, 80]]);
        assert_eq!(group(b, &mut labels, 0.3).len(), 2);
        // overlapping by less than half the narrower width (6 of 16 columns)
        let (b, mut labels, _) = labelled(w, h, &[[10, 10, 25, 40], [20, 45, 35, 80]]);
        assert_eq!(group(b, &mut labels, 0.3).len(), 2);
        // grouping off
        let (b, mut labels, _) = labelled(w, h, &[[42, 10, 53, 29], [40, 45, 55, 89]]);
        assert_eq!(group(b, &mut labels, -1.0).len(), 2);
    }

    #[test]
    fn three_fragments_group_transitively_in_label_order() {
        // head, shirt, legs, each gap 5 rows, and a separate blob to the right
        let (w, h) = (100, 100);
        let (b, mut labels, _) = labelled(
            w,
            h,
            &[
                [44, 5, 51, 14],
                [70, 5, 80, 30],
                [40, 20, 55, 45],
                [41, 51, 54, 90],
            ],
        );
        assert_eq!(b.len(), 4);
        let g = group(b, &mut labels, 0.3);
        assert_eq!(g.len(), 2);
        assert_eq!(g[0].bbox, [40, 5, 55, 90]);
        assert_eq!(g[1].bbox, [70, 5, 80, 30]);
        assert!(g[0].label < g[1].label);
        assert_eq!(labels[60 * w + 45], g[0].label);
    }
}
