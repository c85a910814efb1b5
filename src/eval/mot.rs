//! Tracking metrics (being written).
