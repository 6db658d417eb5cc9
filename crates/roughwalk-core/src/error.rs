//! The core's error type. The binding crate maps each variant to a Python
//! exception class (`TerrainError`, `RobotModelError`, ...).

use std::fmt;

/// Everything the core can refuse, with a message that names the bad value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CoreError {
    /// Bad terrain or signed-distance-field input.
    Terrain(String),
    /// Bad robot description.
    RobotModel(String),
    /// Bad planning input.
    Planning(String),
    /// A shape or value error in arguments that is not specific to a domain.
    InvalidArgument(String),
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoreError::Terrain(m)
            | CoreError::RobotModel(m)
            | CoreError::Planning(m)
            | CoreError::InvalidArgument(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for CoreError {}

/// Result alias used across the core.
pub type CoreResult<T> = Result<T, CoreError>;
