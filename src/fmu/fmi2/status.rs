//! What an FMI 2.0 call returns, and the log categories (FMI 2.0, sections 2.1.3 and
//! 2.1.5).

/// `fmi2Status`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[repr(i32)]
pub enum Status {
    /// `fmi2OK`
    Ok = 0,
    /// `fmi2Warning`
    Warning = 1,
    /// `fmi2Discard`
    Discard = 2,
    /// `fmi2Error`
    Error = 3,
    /// `fmi2Fatal`
    Fatal = 4,
    /// `fmi2Pending`
    Pending = 5,
}

/// A refused call: the status to return and the message already logged.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// Status returned to the master.
    pub status: Status,
    /// Message sent to the logger.
    pub message: String,
}

/// Result of an FMI call.
pub type FmiResult<T = ()> = std::result::Result<T, Refusal>;

/// Log categories, in the order of the model description.
pub const LOG_CATEGORIES: [&str; 4] = [
    "logStatusError",
    "logStatusWarning",
    "logCalls",
    "logEvents",
];

/// A logger: status, category, message.
pub type Logger = Box<dyn FnMut(Status, &str, &str) + Send>;
