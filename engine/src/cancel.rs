//! Stopping a running simulation early. The caller raises a [`Cancel`] flag; the simulation
//! loops poll it every few thousand events or steps (one relaxed atomic load, far below the
//! cost of the work between polls) and the call returns [`cancelled`](Cancel::check)'s error.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::EngineError;

/// Message of the error a cancelled call returns.
pub const CANCELLED: &str = "simulation cancelled";

/// A request to stop, shared by the thread that raises it and the threads that simulate.
#[derive(Debug, Default)]
pub struct Cancel(AtomicBool);

/// A flag nobody raises, for calls that are never cancelled.
pub static NEVER: Cancel = Cancel::new();

impl Cancel {
    /// A flag not (yet) raised.
    pub const fn new() -> Self {
        Cancel(AtomicBool::new(false))
    }

    /// Ask every loop that polls this flag to stop.
    pub fn request(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether a stop was requested.
    #[inline]
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// `Err` ([`CANCELLED`]) once a stop was requested.
    #[inline]
    pub fn check(&self) -> Result<(), EngineError> {
        if self.requested() {
            return Err(EngineError(CANCELLED.to_owned()));
        }
        Ok(())
    }
}
