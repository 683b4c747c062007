//! The memory a job may use, checked before the work that would need it starts.
//!
//! A legal request can still ask for more than the machine has: a garden of a hundred
//! thousand conifers, an automaton with every limit at its maximum, a world of sixteen
//! million voxels. Rather than be killed by the allocator, Sylva estimates what a piece of
//! work will hold in memory before it allocates it and refuses, naming the estimate, the
//! budget and what to change, when it does not fit ([`check`]).
//!
//! The budget is one number for the process: by default half of the machine's memory (at
//! least 1 GiB; 4 GiB where the machine's memory cannot be read), set with
//! [`set_max_memory`] (the command line's `--max-memory`). Estimates are of the large
//! buffers a step allocates (plants, meshes, files, voxels, populations), not of every byte.

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};

/// The budget set by [`set_max_memory`]; 0 means the machine's default.
static MAX_MEMORY: AtomicU64 = AtomicU64::new(0);

/// Work that would not fit in the memory budget.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} would need about {needed} of memory, more than the budget of {budget} (set with \
     `--max-memory`); {advice}"
)]
pub struct OverBudget {
    /// What was asked for, and of which field or flag it follows.
    pub what: String,
    /// The estimate.
    pub needed: Bytes,
    /// The budget.
    pub budget: Bytes,
    /// What to change.
    pub advice: String,
}

/// A size in bytes, shown in KiB, MiB or GiB.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = self.0 as f64;
        match self.0 {
            0..1024 => write!(f, "{} bytes", self.0),
            1024..1_048_576 => write!(f, "{:.1} KiB", b / 1024.0),
            1_048_576..1_073_741_824 => write!(f, "{:.1} MiB", b / 1_048_576.0),
            _ => write!(f, "{:.1} GiB", b / 1_073_741_824.0),
        }
    }
}

/// The default budget: half of the machine's memory, at least 1 GiB (4 GiB when unknown).
pub fn default_max_memory() -> u64 {
    const GIB: u64 = 1 << 30;
    machine_memory().map_or(4 * GIB, |total| (total / 2).max(GIB))
}

/// The machine's memory, from `/proc/meminfo` (Linux).
fn machine_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// The budget in force, in bytes.
pub fn max_memory() -> u64 {
    match MAX_MEMORY.load(Ordering::Relaxed) {
        0 => default_max_memory(),
        set => set,
    }
}

/// Sets the budget for the rest of the process (0 goes back to the machine's default).
pub fn set_max_memory(bytes: u64) {
    MAX_MEMORY.store(bytes, Ordering::Relaxed);
}

/// Refuses work whose estimate `needed` is over the budget. `what` names the work and the
/// field or flag it follows ("a garden of 100000 plants (`--count`)"); `advice` says what
/// to change.
pub fn check(
    needed: u64,
    what: impl fmt::Display,
    advice: impl fmt::Display,
) -> Result<(), OverBudget> {
    let budget = max_memory();
    if needed <= budget {
        Ok(())
    } else {
        Err(OverBudget {
            what: what.to_string(),
            needed: Bytes(needed),
            budget: Bytes(budget),
            advice: advice.to_string(),
        })
    }
}

/// Parses a size: a whole number of bytes, or a number with `K`, `M`, `G` or `T` (powers of
/// 1024; `KiB`, `MB` and the like are read the same way).
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let bad = || format!("expected a size like 512M, 8G or 2000000000; got {text:?}");
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let value: f64 = number.parse().map_err(|_| bad())?;
    let scale: f64 = match unit
        .trim()
        .to_ascii_uppercase()
        .trim_end_matches(['B', 'I'])
    {
        "" => 1.0,
        "K" => 1024.0,
        "M" => 1024.0 * 1024.0,
        "G" => 1024.0 * 1024.0 * 1024.0,
        "T" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => return Err(bad()),
    };
    let bytes = value * scale;
    if bytes.is_finite() && (1.0..=1e18).contains(&bytes) {
        Ok(bytes as u64)
    } else {
        Err(bad())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_and_show() {
        assert_eq!(parse_bytes("512M"), Ok(512 << 20));
        assert_eq!(parse_bytes("8G"), Ok(8 << 30));
        assert_eq!(parse_bytes("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_bytes("2000"), Ok(2000));
        for bad in ["", "G", "-1G", "5X", "1e400", "0"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
        assert_eq!(Bytes(512).to_string(), "512 bytes");
        assert_eq!(Bytes(3 << 29).to_string(), "1.5 GiB");
    }

    #[test]
    fn the_default_fits_the_machine() {
        let d = default_max_memory();
        assert!(d >= 1 << 30);
        assert!(check(d, "all of it", "").is_ok());
        let e = check(d + 1, "a little more (`--count`)", "use fewer plants").unwrap_err();
        assert!(
            e.to_string()
                .contains("a little more (`--count`) would need about")
        );
        assert!(e.to_string().ends_with("use fewer plants"));
    }
}
