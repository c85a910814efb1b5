//! Multi-modal person anchoring and the attention mechanism of BIRON (seed 003: Wrede et al.
//! 2004, §IV; the full papers, Fritsch et al. 2003 "Multi-modal anchoring for human-robot
//! interaction" and Lang et al. 2003, are not at hand, so where the seed is silent — anchor
//! states, gates, timeouts — the choices are ours, named here and kept parameters).
//!
//! A **person anchor** is composed of one **component anchor** per modality ([`component`]):
//! legs (the laser people tracker, [`crate::laser::tracker`]), face (a frontal face,
//! [`crate::vision::faces`]), torso (the colour of the region below the face, followed by the
//! mean-shift colour tracker, [`torso`]) and voice (the GCC-PHAT direction of a sound,
//! [`crate::audio`]). Each component is *grounded* in a step where a percept of its modality
//! was associated with the person, *associated* while its last percept is younger than the
//! modality's timeout, *lost* after. Percepts are associated with persons by bearing within a
//! gate per modality ([`fusion`]); the sound's bearing is corrected for the mouth's height
//! once the person anchor gives range and height ([`crate::audio::doa::azimuth`]), and only
//! its front solution is used ("sound sources in front of the robot").
//!
//! The **attention** state machine ([`attention`]) sorts persons into the seed's three
//! categories (not speaking; speaking but not looking at the robot or not judgeable because
//! out of the camera's view; speaking and looking), selects the person of interest bottom-up,
//! and switches to top-down attention on a greeting from the dialog, keeping the partner in
//! focus until good-bye or the partner's anchor is lost. [`ptu`] turns the camera toward the
//! focus. [`system`] wires the modalities of one robot into one step per camera frame.
//!
//! Not here: speech recognition (the dialog input is a stand-in, see [`system`]), following,
//! object attention, gesture recognition.

pub mod attention;
pub mod component;
pub mod fusion;
pub mod ptu;
pub mod system;
pub mod torso;
pub mod view;

/// Which modalities a run uses (the ablations switch one off).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Modalities {
    pub legs: bool,
    pub faces: bool,
    pub torso: bool,
    pub sound: bool,
}

impl Modalities {
    pub const ALL: Modalities = Modalities {
        legs: true,
        faces: true,
        torso: true,
        sound: true,
    };
}
