//! Pixel counts of a predicted foreground mask against a hand-segmented one, and the
//! precision / recall / F-measure from them (the Wallflower protocol counts FP and FN
//! pixels at one frame).

/// How the shadow value of a GMM mask is scored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShadowAs {
    Background,
    Foreground,
}

/// Confusion counts of a binary foreground decision, in pixels.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MaskCounts {
    pub true_positive: u64,
    pub false_positive: u64,
    pub false_negative: u64,
    pub true_negative: u64,
}

impl MaskCounts {
    /// Count `predicted` (0 background, 255 foreground, any other value a shadow scored as
    /// `shadow`) against `truth` (> 127 foreground). `None` when the lengths differ.
    pub fn count(predicted: &[u8], truth: &[u8], shadow: ShadowAs) -> Option<Self> {
        if predicted.len() != truth.len() {
            return None;
        }
        let mut c = Self::default();
        for (&p, &t) in predicted.iter().zip(truth) {
            let fg = match p {
                0 => false,
                255 => true,
                _ => shadow == ShadowAs::Foreground,
            };
            match (fg, t > 127) {
                (true, true) => c.true_positive += 1,
                (true, false) => c.false_positive += 1,
                (false, true) => c.false_negative += 1,
                (false, false) => c.true_negative += 1,
            }
        }
        Some(c)
    }

    pub fn precision(&self) -> f64 {
        ratio(self.true_positive, self.true_positive + self.false_positive)
    }

    pub fn recall(&self) -> f64 {
        ratio(self.true_positive, self.true_positive + self.false_negative)
    }

    /// Harmonic mean of precision and recall, `2TP / (2TP + FP + FN)`; 0 when undefined.
    pub fn f_measure(&self) -> f64 {
        ratio(
            2 * self.true_positive,
            2 * self.true_positive + self.false_positive + self.false_negative,
        )
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 { 0.0 } else { a as f64 / b as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_f_measure() {
        let pred = [0, 255, 127, 255, 0];
        let truth = [0, 255, 255, 0, 255];
        let bg = MaskCounts::count(&pred, &truth, ShadowAs::Background).expect("same length");
        assert_eq!(
            bg,
            MaskCounts {
                true_positive: 1,
                false_positive: 1,
                false_negative: 2,
                true_negative: 1
            }
        );
        assert!((bg.f_measure() - 2.0 / 5.0).abs() < 1e-12);
        let fg = MaskCounts::count(&pred, &truth, ShadowAs::Foreground).expect("same length");
        assert_eq!(fg.true_positive, 2);
        assert!((fg.f_measure() - 4.0 / 6.0).abs() < 1e-12);
        assert_eq!(
            MaskCounts::count(&pred, &truth[..2], ShadowAs::Background),
            None
        );
        assert_eq!(MaskCounts::default().f_measure(), 0.0);
    }
}
