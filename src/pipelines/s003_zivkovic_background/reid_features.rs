//! Re-identification, from cached frames to observations (seed 003 §V): the colour spaces, the
//! local tracks as observations y_k = {o_k, d_k} — the feature of each pixel set and colour
//! space averaged over the track's frames, as the paper does ("the averages over features
//! computed from multiple frames"), and the entered / left times — and what the training
//! split fits: the prior moved to the features' units and the nearest-neighbour threshold.
//!
//! **Colour spaces.** `normalised` (the default, the paper's "color-channel normalized space
//! [8]"): Drew, Wei & Li (ICCV 1998) first divide each channel of the image by its mean over
//! the image, which cancels a change of the light's colour and intensity per channel (a
//! diagonal model); they then keep only chromaticity for their histograms, but the paper
//! averages "3D" colours per region, so the feature stops after the channel normalisation:
//! region mean / frame mean per channel (pixel-wise normalisation and the region mean
//! commute). `ln`: the logarithm of the same ratio (the feature before issue 31: the frame's
//! mean colour at 0). `raw`: RGB / 255. `chromaticity` (issue 31, round 6): Drew, Wei & Li's
//! second step as well — each region's channel-normalised colour divided by the sum of its
//! three channels (r + g + b = 1 per region), which also cancels the region's brightness
//! (shading, the person's distance to a lamp); taken of the region's mean, not per pixel.

use std::collections::BTreeMap;

use super::reid::{BOX, EXACT, FILLED, PERSON, ReidFrameRow};
use super::reid_params::ReidParams;
use crate::track::reid::Span;

/// Which pixels of a box a feature averages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum PixelSet {
    /// The tracker's own foreground (the default).
    Person,
    /// The tracker's foreground with each row filled between its first and last pixel.
    Filled,
    /// The synthesizer's per-person mask (the ceiling).
    Exact,
    /// Every pixel of the box.
    Box,
}

impl PixelSet {
    pub const ALL: [PixelSet; 4] = [
        PixelSet::Person,
        PixelSet::Filled,
        PixelSet::Exact,
        PixelSet::Box,
    ];

    /// The `pixels` value of its cached rows.
    pub fn key(self) -> &'static str {
        match self {
            PixelSet::Person => PERSON,
            PixelSet::Filled => FILLED,
            PixelSet::Exact => EXACT,
            PixelSet::Box => BOX,
        }
    }
}

/// The colour space of a feature (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Space {
    Normalised,
    Ln,
    Raw,
    Chromaticity,
}

impl Space {
    pub const ALL: [Space; 4] = [
        Space::Normalised,
        Space::Ln,
        Space::Raw,
        Space::Chromaticity,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Space::Normalised => "channel-normalised",
            Space::Ln => "ln channel-normalised",
            Space::Raw => "raw RGB",
            Space::Chromaticity => "channel-normalised chromaticity",
        }
    }

    /// One frame's 9-D feature from the raw region means and the frame's channel means.
    pub fn of(self, means: [f64; 9], frame: [f64; 3]) -> [f64; 9] {
        let normalised: [f64; 9] = std::array::from_fn(|i| means[i] / frame[i % 3]);
        std::array::from_fn(|i| match self {
            Space::Normalised => normalised[i],
            Space::Ln => (means[i].max(1.0) / frame[i % 3]).ln(),
            Space::Raw => means[i] / 255.0,
            Space::Chromaticity => {
                let region = &normalised[3 * (i / 3)..3 * (i / 3) + 3];
                let sum: f64 = region.iter().sum();
                if sum > 0.0 {
                    normalised[i] / sum
                } else {
                    1.0 / 3.0
                }
            }
        })
    }
}

/// A feature variant: whose pixels, in which space.
pub(super) type Feature = (PixelSet, Space);

/// One local track as an observation y_k = {o_k, d_k}.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Observation {
    /// The track id (system) or person id (truth) it came from.
    pub id: i64,
    /// The person it shows (system tracks: the most frequent match; `None`: no person).
    pub truth: Option<i64>,
    pub span: Span,
    /// Frames of the track (boxes seen).
    pub frames: usize,
    /// Per feature variant: the mean feature and how many frames gave it (absent: none did).
    pub features: BTreeMap<Feature, ([f64; 9], usize)>,
}

impl Observation {
    pub fn feature(&self, f: Feature) -> Option<&[f64; 9]> {
        self.features.get(&f).map(|(x, _)| x)
    }

    /// Frames that gave variant `f` (0 when none).
    pub fn feature_frames(&self, f: Feature) -> usize {
        self.features.get(&f).map_or(0, |(_, n)| *n)
    }
}

/// Local tracks of `source` from the per-frame rows: a person's (or track's) frames — those
/// with a box row — split where it is unseen for more than `max_gap_s`; tracks shorter than
/// `min_frames` dropped. Ordered by when they ended (the filter's order), then start and id.
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
    for (id, mut all) in by_id {
        all.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        let boxes: Vec<&ReidFrameRow> = all.iter().copied().filter(|r| r.pixels == BOX).collect();
        let mut start = 0;
        for i in 1..=boxes.len() {
            let split = i == boxes.len() || boxes[i].t_s - boxes[i - 1].t_s > p.max_gap_s;
            if split {
                let piece = &boxes[start..i];
                if piece.len() >= p.min_frames {
                    let (enter, leave) = (piece[0].t_s, piece[piece.len() - 1].t_s);
                    let inside: Vec<&ReidFrameRow> = all
                        .iter()
                        .copied()
                        .filter(|r| r.t_s >= enter && r.t_s <= leave)
                        .collect();
                    out.push(observation(id, piece, &inside));
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

/// One observation from its box rows `piece` and every row of its span `inside`.
fn observation(id: i64, piece: &[&ReidFrameRow], inside: &[&ReidFrameRow]) -> Observation {
    let mut features = BTreeMap::new();
    for set in PixelSet::ALL {
        let rows: Vec<&&ReidFrameRow> = inside.iter().filter(|r| r.pixels == set.key()).collect();
        if rows.is_empty() {
            continue;
        }
        let n = rows.len() as f64;
        for space in Space::ALL {
            let mut m = [0.0; 9];
            for r in &rows {
                for (acc, v) in m.iter_mut().zip(space.of(r.means(), r.frame_means())) {
                    *acc += v / n;
                }
            }
            features.insert((set, space), (m, rows.len()));
        }
    }
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
        features,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chromaticity_divides_each_regions_normalised_colour_by_its_sum() {
        let frame = [50.0, 50.0, 100.0];
        let means = [100.0, 50.0, 50.0, 10.0, 10.0, 20.0, 0.0, 0.0, 0.0];
        let c = Space::Chromaticity.of(means, frame);
        // region 1: normalised (2, 1, 0.5), sum 3.5; region 2: (0.2, 0.2, 0.2); region 3 black
        let want = [
            2.0 / 3.5,
            1.0 / 3.5,
            0.5 / 3.5,
            1.0 / 3.0,
            1.0 / 3.0,
            1.0 / 3.0,
        ];
        for (got, want) in c.iter().zip(want) {
            assert!((got - want).abs() < 1e-12, "{c:?}");
        }
        assert_eq!(c[6..], [1.0 / 3.0; 3], "a black region is grey");
        // a brighter region (shading, a lamp) has the same chromaticity; the normalised
        // colour doubles
        let brighter = means.map(|v| 2.0 * v);
        assert_eq!(Space::Chromaticity.of(brighter, frame)[..6], c[..6]);
        assert_eq!(Space::Normalised.of(brighter, frame)[0], 4.0);
    }

    /// A box row and a person row of one frame: region means `v` everywhere, frame means 100.
    fn rows(t_s: f64, id: i64, v: f64, truth_id: Option<i64>, source: &str) -> Vec<ReidFrameRow> {
        let head = (0, t_s, source, id, truth_id);
        [BOX, PERSON]
            .iter()
            .map(|set| ReidFrameRow::new(head, set, 50, [100.0; 3], [v; 9]))
            .collect()
    }

    #[test]
    fn the_colour_spaces_of_one_frame() {
        let means = [50.0, 100.0, 200.0, 0.0, 0.0, 0.0, 255.0, 255.0, 255.0];
        let frame = [100.0, 50.0, 200.0];
        let n = Space::Normalised.of(means, frame);
        assert_eq!(n[..3], [0.5, 2.0, 1.0]);
        assert_eq!(n[6..], [2.55, 5.1, 1.275]);
        let l = Space::Ln.of(means, frame);
        assert!((l[0] - 0.5f64.ln()).abs() < 1e-15);
        assert!(
            (l[3] - (1.0f64 / 100.0).ln()).abs() < 1e-15,
            "0 → 1 grey level"
        );
        assert_eq!(Space::Raw.of(means, frame)[6], 1.0);
    }

    #[test]
    fn tracks_split_at_gaps_average_their_features_and_vote_their_person() {
        let p = ReidParams {
            max_gap_s: 1.0,
            min_frames: 2,
            ..ReidParams::default()
        };
        let mut all = Vec::new();
        all.extend(rows(0.0, 7, 100.0, Some(1), "system"));
        all.extend(rows(0.5, 7, 300.0, Some(1), "system"));
        all.extend(rows(1.0, 7, 200.0, Some(2), "system"));
        // a frame whose person pixels gave nothing: its box row only
        all.truncate(all.len() - 1);
        // 2.5 s gap: a new track, of one frame only → dropped
        all.extend(rows(3.5, 7, 900.0, None, "system"));
        all.extend(rows(0.2, 3, 100.0, None, "truth"));
        all.extend(rows(0.4, 3, 100.0, None, "truth"));
        let sys = observations(&all, "system", &p);
        assert_eq!(sys.len(), 1);
        assert_eq!(sys[0].truth, Some(1), "two of three frames on person 1");
        assert_eq!(
            (sys[0].span.enter, sys[0].span.leave, sys[0].frames),
            (0.0, 1.0, 3)
        );
        let norm = |set| (set, Space::Normalised);
        assert_eq!(sys[0].feature(norm(PixelSet::Box)).map(|f| f[0]), Some(2.0));
        assert_eq!(sys[0].feature_frames(norm(PixelSet::Box)), 3);
        // the person set: the two frames that gave it
        assert_eq!(
            sys[0].feature(norm(PixelSet::Person)).map(|f| f[0]),
            Some(2.0)
        );
        assert_eq!(sys[0].feature_frames(norm(PixelSet::Person)), 2);
        assert_eq!(sys[0].feature(norm(PixelSet::Exact)), None);
        assert_eq!(sys[0].feature_frames(norm(PixelSet::Exact)), 0);
        let truth = observations(&all, "truth", &p);
        assert_eq!(truth[0].truth, Some(3));
    }
}
