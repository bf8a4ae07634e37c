//! Errors raised by the engine: every refused value names the parameter, the
//! value and the range it must lie in.

use std::fmt;

/// An error from building or running a model.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A parameter outside its physical range.
    Parameter {
        /// Parameter name, in the words of the thesis (e.g. `track.pad.stiffness`).
        name: String,
        /// The value given.
        value: f64,
        /// The allowed range, in words (e.g. `> 0 N/m`).
        allowed: String,
    },
    /// The time step breaks the stability limit of the explicit scheme.
    UnstableTimeStep {
        /// Requested step (s).
        dt: f64,
        /// Critical step computed from the parameters (s).
        critical: f64,
        /// Which part of the model sets the limit.
        limit: String,
    },
    /// A wheel reached (or started outside) the fixed ends of the track.
    OffTrack {
        /// Wheel position along the track (m).
        position: f64,
        /// The track's running length (m), [`crate::track::TrackParams::running_length`].
        length: f64,
        /// Simulation time (s).
        time: f64,
    },
    /// A state became non-finite during the run.
    NonFinite {
        /// Which quantity.
        what: String,
        /// Simulation time (s).
        time: f64,
    },
    /// A value no physical run reaches (see [`crate::limits`]): the scheme diverged or
    /// the inputs are not a running wheel.
    Diverged {
        /// Which quantity, with its unit (e.g. `contact force on the left wheel (N)`).
        what: String,
        /// Its value.
        value: f64,
        /// The bound it passed.
        limit: f64,
        /// Simulation time (s).
        time: f64,
        /// The likely cause, in words.
        cause: String,
    },
    /// A request this model does not support.
    Unsupported(String),
    /// A table (a measured profile) that cannot be read: the parameter, the file or
    /// line, and what is wrong, in words.
    Table(String),
    /// An input value the step that would use it refuses (nothing moves).
    Input {
        /// The input's name.
        name: String,
        /// Its value.
        value: f64,
        /// The allowed values, in words.
        allowed: String,
    },
}

/// A number for a message: plain where that is short, in exponent form otherwise.
pub fn num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Parameter {
                name,
                value,
                allowed,
            } => write!(
                f,
                "parameter `{name}` = {} is out of range: allowed {allowed}",
                num(*value)
            ),
            Error::UnstableTimeStep {
                dt,
                critical,
                limit,
            } => write!(
                f,
                "time step dt = {dt:e} s exceeds the critical step {critical:e} s of the explicit \
                 central-difference scheme (limit set by {limit}); use dt <= {critical:e} s"
            ),
            Error::OffTrack {
                position,
                length,
                time,
            } => write!(
                f,
                "wheel at position {position} m is outside the track's running length (0, \
                 {length}) m at t = {time} s (the last span, to the fixed rail end, carries no \
                 wheel: the clamped end holds the rail at zero there): lengthen the track, \
                 shorten the run or move the start position"
            ),
            Error::NonFinite { what, time } => {
                write!(f, "{what} became non-finite at t = {time} s")
            }
            Error::Diverged {
                what,
                value,
                limit,
                time,
                cause,
            } => write!(
                f,
                "{what} = {} at t = {time} s is beyond {}, which no physical run reaches: {cause}",
                num(*value),
                num(*limit)
            ),
            Error::Unsupported(what) => write!(f, "not supported: {what}"),
            Error::Table(what) => write!(f, "{what}"),
            Error::Input {
                name,
                value,
                allowed,
            } => write!(
                f,
                "input `{name}` = {} is out of range: allowed {allowed}",
                num(*value)
            ),
        }
    }
}

impl Error {
    /// A parameter refusal of `from` told as one of `to`, the variable that carries the
    /// value where the caller is (the half-car bogie's `vehicle.wheelbase` is
    /// `wheelset[2].offset` of a track with two wheelsets), with `note` after the allowed
    /// range; any other error as it is.
    pub fn renamed(self, from: &str, to: &str, note: &str) -> Error {
        match self {
            Error::Parameter {
                name,
                value,
                allowed,
            } if name == from => Error::Parameter {
                name: to.into(),
                value,
                allowed: format!("{} {note}", allowed.replace(from, to)),
            },
            other => other,
        }
    }
}

impl std::error::Error for Error {}

/// Result alias for the engine.
pub type Result<T> = std::result::Result<T, Error>;

/// Checks `value > 0` and finite.
pub fn positive(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::Parameter {
            name: name.into(),
            value,
            allowed: format!("finite and > 0 {unit}"),
        })
    }
}

/// Checks `value >= 0` and finite.
pub fn non_negative(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::Parameter {
            name: name.into(),
            value,
            allowed: format!("finite and >= 0 {unit}"),
        })
    }
}

/// Checks that `value` is finite.
pub fn finite(name: &str, value: f64, unit: &str) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::Parameter {
            name: name.into(),
            value,
            allowed: format!("a finite number ({unit})"),
        })
    }
}

/// Builds a parameter error.
pub fn out_of_range(name: &str, value: f64, allowed: impl Into<String>) -> Error {
    Error::Parameter {
        name: name.into(),
        value,
        allowed: allowed.into(),
    }
}
