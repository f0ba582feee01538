//! Flag values as numbers, with a usage error that names the flag.

use std::ffi::OsStr;

use crate::exit::usage;

/// The most levels of secondary rays `-bounces` takes: deeper than any course scene needs
/// (10), and shallow enough that the recursion stays well inside a thread's stack.
pub const MAX_BOUNCES: u32 = 100;

pub(super) fn parse_f32(s: &OsStr, what: &str) -> anyhow::Result<f32> {
    s.to_str()
        .and_then(|t| t.parse::<f32>().ok())
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            usage(format!(
                "{what}: expected a number, found \"{}\"",
                s.display()
            ))
        })
}

/// A whole number of 0 or more (`-bounces 0`), spelled as the course's `atoi` reads one
/// that is valid: digits only.
pub(super) fn parse_count(s: &OsStr, what: &str) -> anyhow::Result<u32> {
    s.to_str()
        .and_then(|t| t.parse::<u32>().ok())
        .ok_or_else(|| {
            usage(format!(
                "{what}: expected a whole number of 0 or more, found \"{}\"",
                s.display()
            ))
        })
}

pub(super) fn parse_u32(s: &OsStr, what: &str) -> anyhow::Result<u32> {
    s.to_str()
        .and_then(|t| t.parse::<u32>().ok())
        .filter(|&v| v > 0)
        .ok_or_else(|| {
            usage(format!(
                "{what}: expected a positive whole number, found \"{}\"",
                s.display()
            ))
        })
}
