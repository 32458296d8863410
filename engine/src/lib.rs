//! Exact event-driven golden model of networks of spiking phase-locked loops (sPLLs).
//!
//! Each sPLL is a temporal difference encoder (TDE: facilitatory and trigger synapses driving a
//! LIF neuron) and a current-controlled oscillator (CCO: a LIF neuron with an offset current and
//! one synapse), wired input → TDE facilitatory, CCO → TDE trigger, TDE → CCO. Between events all
//! state evolves in closed form ([`membrane`]); threshold crossings are exact roots; events follow
//! the thesis's Algorithm 1 ([`spll`]); samples and sPLLs run in parallel ([`network`]).

pub mod cancel;
pub mod error;
pub mod fixed_point;
pub mod gate;
pub mod loihi;
pub mod membrane;
pub mod network;
pub mod nir_graph;
pub mod params;
pub mod readout;
pub mod spll;
pub mod threads;

#[cfg(feature = "python")]
mod python;

pub use cancel::Cancel;
pub use error::EngineError;
pub use gate::GateTable;
pub use network::{simulate, simulate_batch, RunConfig, SampleResult};
pub use params::{SpllParams, N_PARAMS, PARAM_NAMES};
pub use readout::{Decision, Readout};
pub use spll::{Recorder, SpllState, STATE_LEN};
