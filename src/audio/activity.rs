//! Which audio blocks hold a directional sound worth localising: the block's energy stands
//! above the background noise and the two microphones agree on one delay. The seed does not
//! say how BIRON detects speech; this is the classic pair of tests, chosen here:
//!
//! - the noise floor is the smallest block energy of the last [`ActivityParams::floor_window_s`]
//!   seconds (minimum statistics, Martin 2001, without the bias correction: blocks of a few
//!   thousand samples vary little), and a block is loud when its energy is at least
//!   [`ActivityParams::energy_ratio_db`] above it;
//! - its GCC-PHAT peak ([`super::gcc_phat::Delay::peak`]) is at least
//!   [`ActivityParams::min_peak`] (diffuse noise spreads the correlation, a talker focuses it).
//!
//! Not a speech/non-speech classifier: any loud directional sound passes.

use std::collections::VecDeque;

/// Voice activity settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActivityParams {
    /// Span of the minimum-statistics noise floor (s).
    pub floor_window_s: f64,
    /// Least block energy over the floor (dB).
    pub energy_ratio_db: f64,
    /// Least GCC-PHAT peak height.
    pub min_peak: f64,
}

impl Default for ActivityParams {
    /// A floor over 8 s (longer than an utterance, so speech does not become the floor) and
    /// 6 dB (speech at the robot is louder than the room's noise by more than that at the
    /// SNRs of the `biron_home` grid but 0 dB), a priori; a PHAT peak of 0.1, chosen on the
    /// quick profile's first session: at the nominal condition (RT60 0.3 s, SNR 10 dB)
    /// speech blocks peak at 0.09–0.19 and noise alone at about 0.14, so there the peak
    /// cannot tell them apart and the energy decides (with 0.2, no block was ever active).
    fn default() -> Self {
        ActivityParams {
            floor_window_s: 8.0,
            energy_ratio_db: 6.0,
            min_peak: 0.1,
        }
    }
}

/// Mean square of two channels over a block.
pub fn block_energy(x0: &[f32], x1: &[f32]) -> f64 {
    let n = x0.len() + x1.len();
    if n == 0 {
        return 0.0;
    }
    let s: f64 = x0
        .iter()
        .chain(x1)
        .map(|&v| f64::from(v) * f64::from(v))
        .sum();
    s / n as f64
}

/// The running voice-activity decision (feed blocks in time order).
#[derive(Debug, Clone)]
pub struct Activity {
    pub params: ActivityParams,
    /// `(time, energy)` of the blocks within the floor window, increasing energies (a
    /// monotone queue: its front is the window's minimum).
    window: VecDeque<(f64, f64)>,
}

impl Activity {
    pub fn new(params: ActivityParams) -> Activity {
        Activity {
            params,
            window: VecDeque::new(),
        }
    }

    /// The noise floor now (the least energy in the window), if any block was seen.
    pub fn floor(&self) -> Option<f64> {
        self.window.front().map(|w| w.1)
    }

    /// Add the block at `t_s` with `energy` and GCC-PHAT `peak`; true when it is active.
    pub fn step(&mut self, t_s: f64, energy: f64, peak: f64) -> bool {
        while self
            .window
            .front()
            .is_some_and(|w| w.0 < t_s - self.params.floor_window_s)
        {
            self.window.pop_front();
        }
        while self.window.back().is_some_and(|w| w.1 >= energy) {
            self.window.pop_back();
        }
        self.window.push_back((t_s, energy));
        let floor = self.floor().unwrap_or(energy);
        let ratio = 10f64.powf(self.params.energy_ratio_db / 10.0);
        energy >= floor * ratio && peak >= self.params.min_peak
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_loud_coherent_block_over_a_quiet_floor_is_active_and_the_floor_forgets() {
        let mut a = Activity::new(ActivityParams::default());
        for k in 0..10 {
            assert!(
                !a.step(f64::from(k) * 0.1, 1.0, 0.9),
                "the first blocks set the floor"
            );
        }
        assert_eq!(a.floor(), Some(1.0));
        assert!(a.step(1.0, 4.0, 0.5), "6 dB over the floor");
        assert!(!a.step(1.1, 3.9, 0.5), "just under 6 dB");
        let incoherent = 0.5 * a.params.min_peak;
        assert!(!a.step(1.2, 10.0, incoherent), "loud but incoherent");
        // the quiet blocks leave the 8 s window: the floor rises to the loud ones
        for k in 0..100 {
            a.step(1.3 + f64::from(k) * 0.1, 10.0, 0.5);
        }
        assert_eq!(a.floor(), Some(10.0));
    }

    #[test]
    fn block_energy_is_the_mean_square_of_both_channels() {
        assert_eq!(block_energy(&[1.0, -1.0], &[2.0, 0.0]), 1.5);
        assert_eq!(block_energy(&[], &[]), 0.0);
    }
}
