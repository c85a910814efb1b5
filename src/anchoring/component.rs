//! A component anchor: one modality's link to a person (Fritsch et al. 2003's anchoring, as
//! seed 003 summarises it). Its state at time t: **grounded** when a percept was associated
//! within the last [`GROUNDED_S`] (one step), **associated** while the last percept is at most
//! `timeout_s` old (the person is predicted, not seen), **lost** after, or before any percept.

/// A percept within this long (s) grounds the component: one 10 Hz step with slack.
pub const GROUNDED_S: f64 = 0.15;

/// A component's state.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum State {
    Lost,
    Associated,
    Grounded,
}

impl State {
    pub fn name(self) -> &'static str {
        match self {
            State::Lost => "lost",
            State::Associated => "associated",
            State::Grounded => "grounded",
        }
    }
}

/// One modality's component anchor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    /// Time of the last associated percept (s).
    pub last_s: Option<f64>,
    pub timeout_s: f64,
}

impl Component {
    pub fn new(timeout_s: f64) -> Component {
        Component {
            last_s: None,
            timeout_s,
        }
    }

    /// A percept was associated at `t_s`.
    pub fn ground(&mut self, t_s: f64) {
        self.last_s = Some(self.last_s.map_or(t_s, |l| l.max(t_s)));
    }

    pub fn state(&self, t_s: f64) -> State {
        match self.last_s {
            Some(l) if t_s - l <= GROUNDED_S => State::Grounded,
            Some(l) if t_s - l <= self.timeout_s => State::Associated,
            _ => State::Lost,
        }
    }

    /// Grounded or associated.
    pub fn alive(&self, t_s: f64) -> bool {
        self.state(t_s) != State::Lost
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_component_is_grounded_then_associated_then_lost() {
        let mut c = Component::new(0.5);
        assert_eq!(c.state(0.0), State::Lost, "no percept yet");
        c.ground(1.0);
        assert_eq!(c.state(1.0), State::Grounded);
        assert_eq!(c.state(1.15), State::Grounded);
        assert_eq!(c.state(1.2), State::Associated);
        assert_eq!(c.state(1.5), State::Associated);
        assert_eq!(c.state(1.51), State::Lost);
        c.ground(0.9); // an older percept never moves the anchor back in time
        assert_eq!(c.last_s, Some(1.0));
    }
}
