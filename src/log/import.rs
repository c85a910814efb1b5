//! Importers: public multi-camera datasets written as session logs in the project's log
//! contract (`CameraInfo`, `/tf_static`, `vision_msgs/msg/Detection2DArray` per camera and the
//! `/ground_truth/people` JSON of [`crate::groundtruth`]), so that the pipelines read them like
//! any other log. Each importer is a pure reading of the dataset's files into typed parts plus
//! one writing step through [`super::SessionWriter`] (atomic: scratch file + rename).
//!
//! - [`detector_noise`]: a detector model of our own (drops, edge jitter, false person-shaped
//!   boxes; seeded) applied to exact boxes before they are written or tracked.
//! - [`wildtrack`]: WILDTRACK (Chavdarova et al. 2018): 7 calibrated HD cameras, annotated
//!   boxes and ground positions.

pub mod detector_noise;
pub mod wildtrack;

/// Why an import failed; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    // `error`, not `source`: a source would be printed twice in an error chain
    #[error("{path}: {error}")]
    Io { path: String, error: std::io::Error },
    #[error("{path}: {reason}")]
    Parse { path: String, reason: String },
    #[error(transparent)]
    Log(#[from] super::LogError),
}

impl ImportError {
    pub(crate) fn parse(path: &std::path::Path, reason: impl Into<String>) -> ImportError {
        ImportError::Parse {
            path: path.display().to_string(),
            reason: reason.into(),
        }
    }
}

/// Read a whole text file (error naming it).
pub(crate) fn read_text(path: &std::path::Path) -> Result<String, ImportError> {
    std::fs::read_to_string(path).map_err(|error| ImportError::Io {
        path: path.display().to_string(),
        error,
    })
}
