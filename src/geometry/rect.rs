//! Axis-aligned rectangles in pixels as corners `[x0, y0, x1, y1]` (x1 ≥ x0, y1 ≥ y0 for a
//! non-empty box): overlap measures shared by detectors, 2-D trackers and their evaluation.

/// Area of a box; a box with a negative side counts as empty.
pub fn area(r: &[f64; 4]) -> f64 {
    (r[2] - r[0]).max(0.0) * (r[3] - r[1]).max(0.0)
}

/// Area of the intersection of two boxes (0 when they do not overlap).
pub fn intersection(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let iw = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
    let ih = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
    iw * ih
}

/// Intersection over union, 0 when the boxes do not overlap.
pub fn iou(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let inter = intersection(a, b);
    if inter <= 0.0 {
        return 0.0;
    }
    inter / (area(a) + area(b) - inter)
}

/// Fraction of box `a`'s area inside box `b` (0 for an empty `a`).
pub fn contained(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let area_a = area(a);
    if area_a <= 0.0 {
        0.0
    } else {
        intersection(a, b) / area_a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms_of_two_offset_squares() {
        let a = [0.0, 0.0, 2.0, 2.0];
        let b = [1.0, 1.0, 3.0, 3.0];
        assert_eq!(intersection(&a, &b), 1.0);
        assert_eq!(iou(&a, &b), 1.0 / 7.0);
        assert_eq!(contained(&a, &b), 0.25);
        assert_eq!(iou(&a, &a), 1.0);
        assert_eq!(iou(&a, &[5.0, 5.0, 6.0, 6.0]), 0.0);
        assert_eq!(contained(&[1.0, 1.0, 1.0, 3.0], &a), 0.0);
    }
}
