//! See tests/import.rs.
