//! Errors the engine reports instead of panicking: every one names what is wrong and where.

use std::fmt;

/// Invalid input to the engine. Converted to Python's `ValueError` by the bindings.
#[derive(Clone, Debug, PartialEq)]
pub struct EngineError(pub String);

impl fmt::Display for EngineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for EngineError {}

/// Shorthand for building an `Err(EngineError)` from a formatted message.
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err($crate::error::EngineError(format!($($arg)*)))
    };
}
pub(crate) use bail;
