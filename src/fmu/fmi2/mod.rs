//! A model-independent FMI 2.0 co-simulation layer: the state machine as one table of
//! allowed phases per function ([`CALLS`]), value access through the variable table,
//! the master's clock, FMU states and logging, for any model that implements
//! [`Model`]. Nothing here knows wheels or tracks.

mod calls;
mod derivatives;
mod instance;
mod model;
mod states;
mod status;
mod step;
mod values;

#[cfg(test)]
pub(crate) use calls::ALL;
pub use calls::{Allowed, CALLS, Call, Phase};
pub use instance::Instance;
pub use model::{Model, OutputFault, StepError, StepFault, StepWarning, WORSENED, Warned};
#[cfg(test)]
pub(crate) use states::MAGIC;
pub use states::Snapshot;
pub use status::{FmiResult, LOG_CATEGORIES, Logger, Refusal, Status};
