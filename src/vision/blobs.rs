//! Blobs of a foreground mask: connected components with their moments (area, centroid,
//! second-order central moments — the ellipse of Zivkovic & Kröse, CVPR 2004, eq. 16 — and
//! bounding box), and the binary majority filter applied before labelling.
//!
//! Only pixels equal to the given object value count: with the GMM's masks (0 background,
//! 127 shadow, 255 foreground) labelling `FOREGROUND` removes the shadow pixels, as the
//! home-tour system does (Zajdel, Zivkovic & Kröse, ICRA 2005, section III-A: "extended with a
//! shadow-pixel removal").
//!
//! **Why our own labelling and not `imageproc`.** Two raster passes with a union-find over
//! provisional labels give the labels *and* every blob's moments in the same sweep, in exact
//! integer arithmetic, with labels numbered in raster order of each blob's first pixel (so the
//! output is a pure function of the mask). It is ~100 lines; `imageproc::region_labelling`
//! would add a dependency tree (and its build time) and a second pass for the moments.
//!
//! Not here: morphology beyond the 3×3 majority filter, contour tracing, holes, blob merging
//! (the local tracker groups the fragments of one person and merges fragments near a track).

use super::ellipse::Ellipse;
use nalgebra::{Matrix2, Point2};

/// Which neighbours touch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Connectivity {
    /// Left, right, up, down.
    Four,
    /// The 4 plus the diagonals.
    #[default]
    Eight,
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BlobError {
    #[error("mask has {have} bytes, a {width}x{height} image needs {need}")]
    MaskSize {
        have: usize,
        need: usize,
        width: usize,
        height: usize,
    },
    #[error("label buffer has {have} entries, the mask has {need} pixels")]
    LabelSize { have: usize, need: usize },
}

/// Raw moments of a pixel set, exact (`m_pq = Σ xᵖ yᵠ` over its pixels).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Moments {
    pub m00: u64,
    pub m10: u64,
    pub m01: u64,
    pub m20: u64,
    pub m11: u64,
    pub m02: u64,
}

impl Moments {
    /// Add pixel (x, y).
    pub fn add_pixel(&mut self, x: u64, y: u64) {
        self.m00 += 1;
        self.m10 += x;
        self.m01 += y;
        self.m20 += x * x;
        self.m11 += x * y;
        self.m02 += y * y;
    }

    /// The moments of the union of two disjoint pixel sets.
    pub fn merged(&self, o: &Moments) -> Moments {
        Moments {
            m00: self.m00 + o.m00,
            m10: self.m10 + o.m10,
            m01: self.m01 + o.m01,
            m20: self.m20 + o.m20,
            m11: self.m11 + o.m11,
            m02: self.m02 + o.m02,
        }
    }

    /// Centroid, `None` for an empty set.
    pub fn centroid(&self) -> Option<Point2<f64>> {
        (self.m00 > 0).then(|| {
            let n = self.m00 as f64;
            Point2::new(self.m10 as f64 / n, self.m01 as f64 / n)
        })
    }

    /// Central second moments divided by the area (the covariance of the pixel positions,
    /// eq. 16 of the EM-like tracker normalised by the pixel count). Computed from the exact
    /// integer sums as `(n Σx² − (Σx)²) / n²` so large offsets lose no precision.
    pub fn covariance(&self) -> Option<Matrix2<f64>> {
        if self.m00 == 0 {
            return None;
        }
        let n = i128::from(self.m00);
        let (sx, sy) = (i128::from(self.m10), i128::from(self.m01));
        let cxx = n * i128::from(self.m20) - sx * sx;
        let cxy = n * i128::from(self.m11) - sx * sy;
        let cyy = n * i128::from(self.m02) - sy * sy;
        let n2 = (n * n) as f64;
        Some(Matrix2::new(
            cxx as f64 / n2,
            cxy as f64 / n2,
            cxy as f64 / n2,
            cyy as f64 / n2,
        ))
    }

    /// The ellipse of the moments, with `min_var` added to both variances (a one-pixel-wide
    /// line or a single pixel would otherwise have a singular covariance; 1/12 px² is the
    /// variance of a uniform pixel footprint).
    pub fn ellipse(&self, min_var: f64) -> Option<Ellipse> {
        let c = self.centroid()?;
        let v = self.covariance()?;
        Some(Ellipse::from_parts(
            c.x,
            c.y,
            v[(0, 0)] + min_var,
            v[(0, 1)],
            v[(1, 1)] + min_var,
        ))
    }
}

/// Variance of a pixel's footprint, 1/12 px²: added to blob covariances.
pub const PIXEL_VARIANCE: f64 = 1.0 / 12.0;

/// One connected component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Blob {
    /// Its value in the label image (1, 2, … in raster order of first pixels; 0 = none).
    pub label: u32,
    pub moments: Moments,
    /// Inclusive pixel bounds `[x0, y0, x1, y1]`.
    pub bbox: [u32; 4],
}

impl Blob {
    pub fn area(&self) -> u64 {
        self.moments.m00
    }

    /// The ellipse of the blob's moments (never `None`: a blob has at least one pixel).
    pub fn ellipse(&self) -> Ellipse {
        self.moments
            .ellipse(PIXEL_VARIANCE)
            .unwrap_or_else(|| Ellipse::from_parts(0.0, 0.0, 1.0, 0.0, 1.0))
    }
}

fn check(mask_len: usize, width: usize, height: usize) -> Result<usize, BlobError> {
    let need = width.saturating_mul(height);
    if mask_len != need {
        return Err(BlobError::MaskSize {
            have: mask_len,
            need,
            width,
            height,
        });
    }
    Ok(need)
}

/// 3×3 binary majority filter: `dst` is `object` where at least 5 of the 9 pixels around (and
/// including) a pixel equal `object`, else 0; outside the image counts as not `object`. Removes
/// isolated noise pixels and fills one-pixel gaps.
pub fn majority_filter(
    src: &[u8],
    width: usize,
    height: usize,
    object: u8,
    dst: &mut [u8],
) -> Result<(), BlobError> {
    let n = check(src.len(), width, height)?;
    if dst.len() != n {
        return Err(BlobError::MaskSize {
            have: dst.len(),
            need: n,
            width,
            height,
        });
    }
    // column sums of 3 rows, then a running window along the row
    let mut col = vec![0u8; width];
    for y in 0..height {
        col.iter_mut().for_each(|c| *c = 0);
        for yy in y.saturating_sub(1)..=(y + 1).min(height - 1) {
            let row = &src[yy * width..(yy + 1) * width];
            for (c, &v) in col.iter_mut().zip(row) {
                *c += u8::from(v == object);
            }
        }
        let out = &mut dst[y * width..(y + 1) * width];
        for x in 0..width {
            let mut s = col[x];
            if x > 0 {
                s += col[x - 1];
            }
            if x + 1 < width {
                s += col[x + 1];
            }
            out[x] = if s >= 5 { object } else { 0 };
        }
    }
    Ok(())
}

fn find(parent: &mut [u32], mut a: u32) -> u32 {
    while parent[a as usize] != a {
        let up = parent[parent[a as usize] as usize];
        parent[a as usize] = up; // path halving
        a = up;
    }
    a
}

fn union(parent: &mut [u32], a: u32, b: u32) -> u32 {
    let (ra, rb) = (find(parent, a), find(parent, b));
    let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
    parent[hi as usize] = lo;
    lo
}

/// Label the connected components of the pixels equal to `object` into `labels` (0 elsewhere)
/// and return them with their moments, in raster order of their first pixel.
pub fn label(
    mask: &[u8],
    width: usize,
    height: usize,
    connectivity: Connectivity,
    object: u8,
    labels: &mut [u32],
) -> Result<Vec<Blob>, BlobError> {
    let n = check(mask.len(), width, height)?;
    if labels.len() != n {
        return Err(BlobError::LabelSize {
            have: labels.len(),
            need: n,
        });
    }
    // pass 1: provisional labels, equivalences in a union-find (label 0 = background)
    let mut parent: Vec<u32> = vec![0];
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            if mask[i] != object {
                labels[i] = 0;
                continue;
            }
            let mut neighbours = [0u32; 4];
            let mut k = 0;
            if x > 0 {
                neighbours[k] = labels[i - 1];
                k += 1;
            }
            if y > 0 {
                neighbours[k] = labels[i - width];
                k += 1;
                if connectivity == Connectivity::Eight {
                    if x > 0 {
                        neighbours[k] = labels[i - width - 1];
                        k += 1;
                    }
                    if x + 1 < width {
                        neighbours[k] = labels[i - width + 1];
                        k += 1;
                    }
                }
            }
            let mut current = 0u32;
            for &l in neighbours[..k].iter().filter(|&&l| l != 0) {
                current = if current == 0 {
                    find(&mut parent, l)
                } else {
                    union(&mut parent, current, l)
                };
            }
            if current == 0 {
                current = parent.len() as u32;
                parent.push(current);
            }
            labels[i] = current;
        }
    }
    // pass 2: final labels in raster order of first pixels, moments and bounds
    let mut final_of = vec![0u32; parent.len()];
    let mut blobs: Vec<Blob> = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            if labels[i] == 0 {
                continue;
            }
            let root = find(&mut parent, labels[i]) as usize;
            if final_of[root] == 0 {
                blobs.push(Blob {
                    label: blobs.len() as u32 + 1,
                    moments: Moments::default(),
                    bbox: [x as u32, y as u32, x as u32, y as u32],
                });
                final_of[root] = blobs.len() as u32;
            }
            let l = final_of[root];
            labels[i] = l;
            let b = &mut blobs[l as usize - 1];
            b.moments.add_pixel(x as u64, y as u64);
            b.bbox[0] = b.bbox[0].min(x as u32);
            b.bbox[2] = b.bbox[2].max(x as u32);
            b.bbox[3] = y as u32;
        }
    }
    Ok(blobs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::gmm::{DEFAULT_SHADOW_VALUE, FOREGROUND};

    /// Mask from ASCII art: `#` foreground, `s` shadow, anything else background.
    fn mask(rows: &[&str]) -> (Vec<u8>, usize, usize) {
        let w = rows[0].len();
        let m = rows
            .iter()
            .flat_map(|r| {
                r.bytes().map(|c| match c {
                    b'#' => FOREGROUND,
                    b's' => DEFAULT_SHADOW_VALUE,
                    _ => 0,
                })
            })
            .collect();
        (m, w, rows.len())
    }

    /// Label image as ASCII (label digits, `.` for 0).
    fn render(labels: &[u32], w: usize) -> Vec<String> {
        labels
            .chunks(w)
            .map(|r| {
                r.iter()
                    .map(|&l| {
                        if l == 0 {
                            '.'
                        } else {
                            char::from_digit(l, 36).unwrap_or('?')
                        }
                    })
                    .collect()
            })
            .collect()
    }

    fn check(rows: &[&str], conn: Connectivity, expected: &[&str], areas: &[u64]) {
        let (m, w, h) = mask(rows);
        let mut labels = vec![0; w * h];
        let blobs = label(&m, w, h, conn, FOREGROUND, &mut labels).expect("sizes");
        assert_eq!(render(&labels, w), expected, "{rows:?} {conn:?}");
        assert_eq!(
            blobs.iter().map(Blob::area).collect::<Vec<_>>(),
            areas,
            "{rows:?}"
        );
        for (k, b) in blobs.iter().enumerate() {
            assert_eq!(b.label as usize, k + 1);
        }
    }

    #[test]
    fn components_four_and_eight_connected() {
        let diag = ["#..#", ".#.#", "..##", "#..."];
        // 8-connectivity joins the diagonal to the right column through (1,1)–(2,2)
        check(
            &diag,
            Connectivity::Eight,
            &["1..1", ".1.1", "..11", "2..."],
            &[6, 1],
        );
        check(
            &diag,
            Connectivity::Four,
            &["1..2", ".3.2", "..22", "4..."],
            &[1, 4, 1, 1],
        );
    }

    #[test]
    fn u_shape_merges_labels_started_apart() {
        // two arms get different provisional labels and meet at the bottom
        check(
            &["#..#", "#..#", "####", "...."],
            Connectivity::Four,
            &["1..1", "1..1", "1111", "...."],
            &[8],
        );
        check(
            &["#.#.#", "#.#.#", "#####"],
            Connectivity::Four,
            &["1.1.1", "1.1.1", "11111"],
            &[11],
        );
    }

    #[test]
    fn shadow_pixels_are_removed() {
        // the shadow column joins two objects only if shadows were kept
        check(
            &["#s#", "#s#"],
            Connectivity::Eight,
            &["1.2", "1.2"],
            &[2, 2],
        );
        check(&["sss", "sss"], Connectivity::Eight, &["...", "..."], &[]);
    }

    #[test]
    fn moments_of_a_rectangle_and_a_diagonal_line() {
        // 6x4 filled rectangle at x 2..=7, y 1..=4
        let mut rows = vec!["..........".to_string(); 6];
        for r in rows.iter_mut().skip(1).take(4) {
            r.replace_range(2..8, "######");
        }
        let rows: Vec<&str> = rows.iter().map(String::as_str).collect();
        let (m, w, h) = mask(&rows);
        let mut labels = vec![0; w * h];
        let blobs = label(&m, w, h, Connectivity::Eight, FOREGROUND, &mut labels).expect("ok");
        assert_eq!(blobs.len(), 1);
        let b = blobs[0];
        assert_eq!(b.area(), 24);
        assert_eq!(b.bbox, [2, 1, 7, 4]);
        let c = b.moments.centroid().expect("non-empty");
        assert_eq!((c.x, c.y), (4.5, 2.5));
        // variance of n consecutive integers is (n² − 1)/12
        let v = b.moments.covariance().expect("non-empty");
        assert!((v[(0, 0)] - 35.0 / 12.0).abs() < 1e-12);
        assert!((v[(1, 1)] - 15.0 / 12.0).abs() < 1e-12);
        assert_eq!(v[(0, 1)], 0.0);

        // a diagonal line x = y: covariance along the diagonal, singular without the footprint
        let line = ["#...", ".#..", "..#.", "...#"];
        let (m, w, h) = mask(&line);
        let mut labels = vec![0; w * h];
        let blobs = label(&m, w, h, Connectivity::Eight, FOREGROUND, &mut labels).expect("ok");
        let v = blobs[0].moments.covariance().expect("non-empty");
        assert!((v[(0, 0)] - 1.25).abs() < 1e-12 && (v[(0, 1)] - 1.25).abs() < 1e-12);
        let e = blobs[0].ellipse();
        assert!(e.is_valid());
        assert!((e.axes().angle - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    }

    #[test]
    fn majority_filter_removes_specks_and_fills_gaps() {
        let (m, w, h) = mask(&["#.....", "......", "..###.", "..#.#.", "..###.", "......"]);
        let mut out = vec![0; w * h];
        majority_filter(&m, w, h, FOREGROUND, &mut out).expect("sizes");
        let on = |x: usize, y: usize| out[y * w + x] == FOREGROUND;
        assert!(!on(0, 0), "isolated pixel removed");
        assert!(on(3, 3), "hole filled");
        assert!(!on(2, 2), "a corner with 3 of 9 set is dropped");
    }

    #[test]
    fn sizes_are_checked() {
        let mut labels = vec![0; 3];
        assert!(matches!(
            label(&[0; 4], 2, 2, Connectivity::Four, 255, &mut labels),
            Err(BlobError::LabelSize { .. })
        ));
        assert!(matches!(
            label(&[0; 5], 2, 2, Connectivity::Four, 255, &mut [0; 4]),
            Err(BlobError::MaskSize { .. })
        ));
    }
}
