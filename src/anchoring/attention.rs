//! BIRON's attention mechanism (seed 003, §IV-B and fig. 3, whose drawing is not in the seed's
//! text): a finite-state machine that selects the person of interest.
//!
//! **Categories** (the seed's three, increasing relevance): 1 not speaking; 2 speaking but not
//! looking at the robot, or looking cannot be judged because the person is out of the
//! camera's view; 3 speaking and looking at the robot ([`category`]).
//!
//! **States.** Bottom-up attention — no partner; "the selection of the person of interest as
//! well as transitions … solely depend on information provided by the person tracking":
//! - `idle`: nobody observed;
//! - `alert`: persons observed, the focus is the most relevant (highest category; a tie
//!   keeps the current focus when it is among the best, else the nearest);
//! - `listen`: the focus is in category 3 — the robot "assumes to be addressed and considers
//!   the corresponding person to be a potential communication partner" (speech recognition
//!   runs only here and in `interact`, seed §V).
//!
//! Top-down attention — "activated as soon as the robot starts to interact with a particular
//! person", i.e. on a greeting from the dialog by the person in focus:
//! - `interact`: the focus stays on the partner "even if it is not speaking"; transitions
//!   are triggered by dialog commands only: good-bye from the partner, or the partner
//!   leaving (its anchor is gone), returns to bottom-up.
//!
//! BIRON's further top-down states (follow, object) are not modelled.

use serde::{Deserialize, Serialize};

/// The attention state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    Idle,
    Alert,
    Listen,
    Interact,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Idle => "idle",
            Mode::Alert => "alert",
            Mode::Listen => "listen",
            Mode::Interact => "interact",
        }
    }

    pub fn top_down(self) -> bool {
        self == Mode::Interact
    }
}

/// A dialog command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Command {
    Greeting,
    Goodbye,
}

/// One observed person as the attention sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observed {
    pub id: u64,
    pub category: u8,
    /// Distance from the robot (m): the tie-break.
    pub distance_m: f64,
}

/// The seed's category of a person: 1, 2 or 3 (see the module doc). `looking` is `None`
/// when it cannot be judged.
pub fn category(speaking: bool, looking: Option<bool>) -> u8 {
    match (speaking, looking) {
        (false, _) => 1,
        (true, Some(true)) => 3,
        (true, _) => 2,
    }
}

/// The state machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Attention {
    pub mode: Mode,
    pub focus: Option<u64>,
}

impl Default for Attention {
    fn default() -> Self {
        Attention {
            mode: Mode::Idle,
            focus: None,
        }
    }
}

impl Attention {
    /// One step: the dialog `commands` heard since the last step (from the person then in
    /// focus), then the persons observed now.
    pub fn step(&mut self, commands: &[(Command, u64)], persons: &[Observed]) {
        for &(c, who) in commands {
            match (c, self.mode) {
                (Command::Greeting, m) if !m.top_down() && self.focus == Some(who) => {
                    self.mode = Mode::Interact;
                }
                (Command::Goodbye, Mode::Interact) if self.focus == Some(who) => {
                    self.mode = Mode::Alert;
                }
                _ => {}
            }
        }
        if self.mode == Mode::Interact {
            if persons.iter().any(|p| Some(p.id) == self.focus) {
                return;
            }
            self.mode = Mode::Alert; // the partner left
        }
        self.bottom_up(persons);
    }

    fn bottom_up(&mut self, persons: &[Observed]) {
        let Some(best) = persons.iter().map(|p| p.category).max() else {
            self.mode = Mode::Idle;
            self.focus = None;
            return;
        };
        let keep = persons
            .iter()
            .any(|p| Some(p.id) == self.focus && p.category == best);
        if !keep {
            self.focus = persons
                .iter()
                .filter(|p| p.category == best)
                .min_by(|a, b| a.distance_m.total_cmp(&b.distance_m).then(a.id.cmp(&b.id)))
                .map(|p| p.id);
        }
        self.mode = if best == 3 { Mode::Listen } else { Mode::Alert };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(id: u64, category: u8, distance_m: f64) -> Observed {
        Observed {
            id,
            category,
            distance_m,
        }
    }

    #[test]
    fn the_three_categories_follow_speaking_and_looking() {
        assert_eq!(category(false, Some(true)), 1);
        assert_eq!(category(false, None), 1);
        assert_eq!(category(true, Some(false)), 2);
        assert_eq!(category(true, None), 2, "out of view: cannot be judged");
        assert_eq!(category(true, Some(true)), 3);
    }

    #[test]
    fn bottom_up_focuses_the_most_relevant_and_keeps_a_tied_focus() {
        let mut a = Attention::default();
        a.step(&[], &[]);
        assert_eq!((a.mode, a.focus), (Mode::Idle, None));
        a.step(&[], &[p(1, 1, 2.0), p(2, 1, 1.5)]);
        assert_eq!(
            (a.mode, a.focus),
            (Mode::Alert, Some(2)),
            "nearest of a tie"
        );
        a.step(&[], &[p(1, 2, 2.0), p(2, 1, 1.5)]);
        assert_eq!((a.mode, a.focus), (Mode::Alert, Some(1)), "a speaker");
        a.step(&[], &[p(1, 1, 2.0), p(2, 1, 1.5)]);
        assert_eq!(a.focus, Some(1), "kept when it stops: still among the best");
        a.step(&[], &[p(1, 2, 2.0), p(2, 3, 1.5)]);
        assert_eq!((a.mode, a.focus), (Mode::Listen, Some(2)));
    }

    #[test]
    fn a_greeting_starts_top_down_attention_that_ignores_other_speakers_until_goodbye() {
        let mut a = Attention::default();
        a.step(&[], &[p(1, 3, 2.0), p(2, 1, 1.0)]);
        assert_eq!(a.focus, Some(1));
        // a greeting from someone not in focus does nothing
        a.step(&[(Command::Greeting, 2)], &[p(1, 3, 2.0), p(2, 1, 1.0)]);
        assert_eq!(a.mode, Mode::Listen);
        a.step(&[(Command::Greeting, 1)], &[p(1, 3, 2.0), p(2, 1, 1.0)]);
        assert_eq!((a.mode, a.focus), (Mode::Interact, Some(1)));
        a.step(&[], &[p(1, 1, 2.0), p(2, 3, 1.0)]);
        assert_eq!(
            (a.mode, a.focus),
            (Mode::Interact, Some(1)),
            "not distracted"
        );
        a.step(&[(Command::Goodbye, 2)], &[p(1, 1, 2.0), p(2, 3, 1.0)]);
        assert_eq!(a.mode, Mode::Interact, "only the partner ends it");
        a.step(&[(Command::Goodbye, 1)], &[p(1, 1, 2.0), p(2, 3, 1.0)]);
        assert_eq!((a.mode, a.focus), (Mode::Listen, Some(2)));
    }

    #[test]
    fn the_partner_leaving_ends_the_interaction() {
        let mut a = Attention::default();
        a.step(&[], &[p(1, 3, 2.0)]);
        a.step(&[(Command::Greeting, 1)], &[p(1, 3, 2.0)]);
        assert_eq!(a.mode, Mode::Interact);
        a.step(&[], &[p(2, 1, 1.0)]);
        assert_eq!((a.mode, a.focus), (Mode::Alert, Some(2)));
    }
}
