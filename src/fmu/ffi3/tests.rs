//! The FMI 3.0 C boundary driven through its exported functions.
