//! A model-independent FMI 3.0 co-simulation layer over the FMI 2.0 one ([`super::fmi2`]):
//! the FMI 3.0 state machine as one table ([`CALLS3`]), its types and its arrays (a
//! per-wheelset variable is one array sized by the structural parameter `wheelsets`),
//! for any model that implements [`super::fmi2::Model`]. The FMI 2.0 layer keeps the
//! values, ranges, clock, model and FMU states; its messages reach the logger in FMI
//! 3.0 terms ([`translate`]).

mod calls;
mod instance;
mod messages;

pub use calls::{Allowed3, CALLS3, Call3, Phase3, fmi3_name};
pub use instance::{Instance3, StepReport};
pub use messages::translate;
