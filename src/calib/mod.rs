//! Calibration: the webcam measurement system of seed 000 ([`external`]).

pub mod external;
