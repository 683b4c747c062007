//! The memory a job may use, checked before the work that would need it starts.
//!
//! A legal request can still ask for more than the machine has: a garden of a hundred
//! thousand conifers, an automaton with every limit at its maximum, a world of sixteen
//! million voxels. Rather than be killed by the allocator, Sylva estimates what a piece of
//! work will hold in memory before it allocates it and refuses, naming the estimate, the
//! budget, where the budget came from and what to change, when it does not fit ([`check`]).
//!
//! The budget is one number for the process, set with [`set_max_memory`] (the command
//! line's `--max-memory`) or else worked out once from the limits the process runs under
//! ([`default_budget`]), taking the least of:
//!
//! - half of the machine's memory (`MemTotal` in `/proc/meminfo`), at least 1 GiB;
//! - half of its cgroup's memory limit (`memory.max` of cgroup v2, `memory.limit_in_bytes`
//!   of cgroup v1; the least along the path from the process's cgroup to the root), which
//!   containers, CI runners and systemd slices set;
//! - half of what its address-space limit (`RLIMIT_AS`, `ulimit -v`) leaves once what is
//!   already mapped when the budget is worked out is taken off: the limit counts virtual
//!   memory (the program, thread stacks, the allocator's arenas), so the other half is room
//!   for those and for what estimates leave out;
//! - half of what its data limit (`RLIMIT_DATA`, `ulimit -d`) leaves, likewise.
//!
//! 4 GiB where none can be read. The limits are read from `/proc` (Linux), so reading
//! them needs no system call of our own; [`Limits`] holds what was read and
//! [`Limits::budget`] chooses, so the choice is tested on text. Estimates are of the large
//! buffers a step allocates (plants, meshes, files, voxels, populations), not of every byte.
//!
//! Time has a budget too, for work whose length a legal input can make absurd (L-system
//! plants at their bounds in a large world): work estimated to take longer than
//! [`max_time`] before its results are written (one hour unless [`set_max_time`], the
//! command line's `--max-time`, says otherwise) is refused by [`check_time`] with its
//! estimate and what to change.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

const GIB: u64 = 1 << 30;

/// The budget set by [`set_max_memory`]; 0 means the default ([`default_budget`]).
static MAX_MEMORY: AtomicU64 = AtomicU64::new(0);

/// The default budget, worked out once.
static DEFAULT: OnceLock<Budget> = OnceLock::new();

/// Work that would not fit in the memory budget.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} would need about {needed} of memory, more than the budget of {budget} ({set_by}); \
     {advice}"
)]
pub struct OverBudget {
    /// What was asked for, and of which field or flag it follows.
    pub what: String,
    /// The estimate.
    pub needed: Bytes,
    /// The budget.
    pub budget: Bytes,
    /// Where the budget came from.
    pub set_by: Source,
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

/// Where a budget came from. Shown in refusals after the budget, as "the budget of 1.9 GiB
/// (half of what the process's address-space limit leaves: RLIMIT_AS 4.0 GiB, 210.3 MiB of
/// it mapped at start; set another with `--max-memory`)".
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// Set with [`set_max_memory`] (`--max-memory`).
    Set,
    /// Half of the machine's memory (at least 1 GiB).
    Machine {
        /// The machine's memory.
        total: u64,
    },
    /// Half of a cgroup's memory limit.
    Cgroup {
        /// The limit.
        limit: u64,
        /// The file it was read from.
        file: PathBuf,
    },
    /// Half of what the address-space limit leaves.
    AddressSpace {
        /// `RLIMIT_AS` (soft).
        limit: u64,
        /// Address space mapped when the budget was worked out (`VmSize`).
        used: u64,
    },
    /// Half of what the data limit leaves.
    Data {
        /// `RLIMIT_DATA` (soft).
        limit: u64,
        /// Data in use when the budget was worked out (`VmData`).
        used: u64,
    },
    /// No limit could be read: 4 GiB.
    Unknown,
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const OTHER: &str = "set another with `--max-memory`";
        match self {
            Source::Set => write!(f, "set with `--max-memory`"),
            Source::Machine { total } => {
                write!(
                    f,
                    "half of the machine's memory of {}; {OTHER}",
                    Bytes(*total)
                )
            }
            Source::Cgroup { limit, file } => write!(
                f,
                "half of the cgroup's memory limit of {} in {}; {OTHER}",
                Bytes(*limit),
                file.display()
            ),
            Source::AddressSpace { limit, used } => write!(
                f,
                "half of what the process's address-space limit leaves: RLIMIT_AS {}, {} of it \
                 mapped at start; {OTHER}",
                Bytes(*limit),
                Bytes(*used)
            ),
            Source::Data { limit, used } => write!(
                f,
                "half of what the process's data limit leaves: RLIMIT_DATA {}, {} of it in use \
                 at start; {OTHER}",
                Bytes(*limit),
                Bytes(*used)
            ),
            Source::Unknown => write!(
                f,
                "the default where the machine's memory cannot be read; {OTHER}"
            ),
        }
    }
}

/// A memory budget and where it came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Bytes.
    pub bytes: u64,
    /// Where it came from.
    pub source: Source,
}

/// The limits a process runs under, as read from the system; each `None` when there is
/// none or it cannot be read. [`Limits::budget`] chooses the budget from them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Limits {
    /// The machine's memory.
    pub machine: Option<u64>,
    /// The least cgroup memory limit over the process's cgroup and its ancestors, and the
    /// file that set it.
    pub cgroup: Option<(u64, PathBuf)>,
    /// The soft `RLIMIT_AS` and the address space mapped now.
    pub address_space: Option<(u64, u64)>,
    /// The soft `RLIMIT_DATA` and the data in use now.
    pub data: Option<(u64, u64)>,
}

impl Limits {
    /// Reads the limits of this process from `/proc` and `/sys/fs/cgroup` (Linux; all
    /// `None` elsewhere).
    pub fn read() -> Limits {
        let read = |p: &Path| std::fs::read_to_string(p).ok();
        let status = read(Path::new("/proc/self/status")).unwrap_or_default();
        let (vm_size, vm_data) = parse_status(&status);
        let (address_space, data) =
            read(Path::new("/proc/self/limits")).map_or((None, None), |text| parse_rlimits(&text));
        let cgroup = match (
            read(Path::new("/proc/self/cgroup")),
            read(Path::new("/proc/self/mountinfo")),
        ) {
            (Some(cgroup), Some(mountinfo)) => cgroup_limit(&cgroup, &mountinfo, &read),
            _ => None,
        };
        Limits {
            machine: read(Path::new("/proc/meminfo")).and_then(|t| parse_meminfo(&t)),
            cgroup,
            address_space: address_space.map(|l| (l, vm_size.unwrap_or(0))),
            data: data.map(|l| (l, vm_data.unwrap_or(0))),
        }
    }

    /// The budget these limits give: the least of half the machine's memory (at least
    /// 1 GiB), half the cgroup limit, and half of what each rlimit leaves over what is in
    /// use; 4 GiB when there is none.
    pub fn budget(&self) -> Budget {
        let mut candidates = Vec::new();
        if let Some(total) = self.machine {
            candidates.push(((total / 2).max(GIB), Source::Machine { total }));
        }
        if let Some((limit, file)) = &self.cgroup {
            candidates.push((
                limit / 2,
                Source::Cgroup {
                    limit: *limit,
                    file: file.clone(),
                },
            ));
        }
        if let Some((limit, used)) = self.address_space {
            candidates.push((
                limit.saturating_sub(used) / 2,
                Source::AddressSpace { limit, used },
            ));
        }
        if let Some((limit, used)) = self.data {
            candidates.push((limit.saturating_sub(used) / 2, Source::Data { limit, used }));
        }
        // The first of the least: the machine before a cgroup before an rlimit.
        let mut best: Option<(u64, Source)> = None;
        for (bytes, source) in candidates {
            if best.as_ref().is_none_or(|(b, _)| bytes < *b) {
                best = Some((bytes, source));
            }
        }
        match best {
            Some((bytes, source)) => Budget { bytes, source },
            None => Budget {
                bytes: 4 * GIB,
                source: Source::Unknown,
            },
        }
    }
}

/// `MemTotal` of `/proc/meminfo`, in bytes.
pub fn parse_meminfo(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// The soft `RLIMIT_AS` ("Max address space") and `RLIMIT_DATA` ("Max data size") of
/// `/proc/self/limits`, in bytes; `None` when unlimited or missing.
pub fn parse_rlimits(text: &str) -> (Option<u64>, Option<u64>) {
    let soft = |name: &str| {
        let rest = text.lines().find_map(|l| l.strip_prefix(name))?;
        rest.split_whitespace().next()?.parse::<u64>().ok()
    };
    (soft("Max address space"), soft("Max data size"))
}

/// `VmSize` and `VmData` of `/proc/self/status`, in bytes.
pub fn parse_status(text: &str) -> (Option<u64>, Option<u64>) {
    let field = |name: &str| {
        let rest = text.lines().find_map(|l| l.strip_prefix(name))?;
        let kib: u64 = rest.split_whitespace().next()?.parse().ok()?;
        kib.checked_mul(1024)
    };
    (field("VmSize:"), field("VmData:"))
}

/// A cgroup limit file's value: bytes, or `None` for `max` (v2) or a value so large it
/// means no limit (v1 writes 2^63 less a page).
pub fn parse_cgroup_limit(text: &str) -> Option<u64> {
    let value: u64 = text.trim().parse().ok()?;
    (value < 1 << 60).then_some(value)
}

/// The least memory limit of the process's cgroup and its ancestors, and the file that
/// set it. `cgroup` is `/proc/self/cgroup`, `mountinfo` is `/proc/self/mountinfo`, and
/// `read` reads a file (tests pass their own). cgroup v2's `memory.max` is read where the
/// unified hierarchy is mounted, cgroup v1's `memory.limit_in_bytes` where the memory
/// controller is; a limit on any ancestor (up to the mount's root) binds the process too.
pub fn cgroup_limit(
    cgroup: &str,
    mountinfo: &str,
    read: &dyn Fn(&Path) -> Option<String>,
) -> Option<(u64, PathBuf)> {
    let mut best: Option<(u64, PathBuf)> = None;
    for line in cgroup.lines() {
        // hierarchy-ID:controllers:path
        let mut parts = line.splitn(3, ':');
        let (Some(_), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        let (file, v2) = if controllers.is_empty() {
            ("memory.max", true)
        } else if controllers.split(',').any(|c| c == "memory") {
            ("memory.limit_in_bytes", false)
        } else {
            continue;
        };
        let Some((root, mount)) = cgroup_mount(mountinfo, v2) else {
            continue;
        };
        if path.split('/').any(|c| c == "..") {
            continue;
        }
        // The process's cgroup as a folder under the mount.
        let relative = path.strip_prefix(root.as_str()).unwrap_or(path);
        let mut dir = mount.clone();
        dir.extend(relative.split('/').filter(|c| !c.is_empty()));
        loop {
            let candidate = dir.join(file);
            if let Some(limit) = read(&candidate).and_then(|t| parse_cgroup_limit(&t))
                && best.as_ref().is_none_or(|(b, _)| limit < *b)
            {
                best = Some((limit, candidate));
            }
            if dir == mount || !dir.pop() {
                break;
            }
        }
    }
    best
}

/// The root and mount point of the cgroup v2 hierarchy (`v2`) or of cgroup v1's memory
/// controller, from `/proc/self/mountinfo`.
fn cgroup_mount(mountinfo: &str, v2: bool) -> Option<(String, PathBuf)> {
    mountinfo.lines().find_map(|line| {
        // id parent major:minor root mount-point options [optional...] - type source super
        let (before, after) = line.split_once(" - ")?;
        let fields: Vec<&str> = before.split(' ').collect();
        let mut after = after.split(' ');
        let fstype = after.next()?;
        let _source = after.next();
        let options = after.next().unwrap_or("");
        let wanted = if v2 {
            fstype == "cgroup2"
        } else {
            fstype == "cgroup" && options.split(',').any(|o| o == "memory")
        };
        (wanted && fields.len() >= 5)
            .then(|| (unescape(fields[3]), PathBuf::from(unescape(fields[4]))))
    })
}

/// Undoes mountinfo's octal escapes (`\\040` for a space).
fn unescape(field: &str) -> String {
    let bytes = field.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let code = (bytes[i] == b'\\')
            .then(|| field.get(i + 1..i + 4))
            .flatten()
            .and_then(|d| u8::from_str_radix(d, 8).ok());
        match code {
            Some(c) => {
                out.push(c);
                i += 4;
            }
            None => {
                out.push(bytes[i]);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The default budget of this process ([`Limits::read`], then [`Limits::budget`]), worked
/// out the first time it is asked for and kept: a front end asks for it when it starts, so
/// that "mapped at start" is what it says.
pub fn default_budget() -> &'static Budget {
    DEFAULT.get_or_init(|| Limits::read().budget())
}

/// The default budget in bytes ([`default_budget`]).
pub fn default_max_memory() -> u64 {
    default_budget().bytes
}

/// The budget in force, in bytes.
pub fn max_memory() -> u64 {
    budget().bytes
}

/// The budget in force and where it came from.
pub fn budget() -> Budget {
    match MAX_MEMORY.load(Ordering::Relaxed) {
        0 => default_budget().clone(),
        bytes => Budget {
            bytes,
            source: Source::Set,
        },
    }
}

/// Sets the budget for the rest of the process (0 goes back to the default).
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
    let budget = budget();
    if needed <= budget.bytes {
        Ok(())
    } else {
        Err(OverBudget {
            what: what.to_string(),
            needed: Bytes(needed),
            budget: Bytes(budget.bytes),
            set_by: budget.source,
            advice: advice.to_string(),
        })
    }
}

/// The time budget by default: an hour.
pub const DEFAULT_MAX_TIME: Duration = Duration::from_secs(3600);

/// The time budget set by [`set_max_time`], in milliseconds; 0 means the default.
static MAX_TIME_MS: AtomicU64 = AtomicU64::new(0);

/// The time budget in force.
pub fn max_time() -> Duration {
    match MAX_TIME_MS.load(Ordering::Relaxed) {
        0 => DEFAULT_MAX_TIME,
        ms => Duration::from_millis(ms),
    }
}

/// Sets the time budget for the rest of the process (zero goes back to the default).
pub fn set_max_time(budget: Duration) {
    let ms = u64::try_from(budget.as_millis()).unwrap_or(u64::MAX);
    MAX_TIME_MS.store(ms, Ordering::Relaxed);
}

/// A length of time, shown in seconds, minutes, hours or days.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct Seconds(pub f64);

impl fmt::Display for Seconds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.0;
        if !s.is_finite() {
            write!(f, "forever")
        } else if s < 10.0 {
            write!(f, "{s:.1} s")
        } else if s < 120.0 {
            write!(f, "{s:.0} s")
        } else if s < 3600.0 {
            write!(f, "{:.1} min", s / 60.0)
        } else if s < 172_800.0 {
            write!(f, "{:.1} h", s / 3600.0)
        } else if s < 3.156e8 {
            write!(f, "{:.0} days", s / 86_400.0)
        } else if s < 3.156e11 {
            write!(f, "{:.0} years", s / 3.156e7)
        } else {
            write!(f, "{:.1e} years", s / 3.156e7)
        }
    }
}

/// Work that would take longer than the time budget.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "{what} would take up to about {estimate}, more than the time budget of {budget} \
     ({set_by}); {advice}"
)]
pub struct OverTime {
    /// What was asked for, and of which fields or flags it follows.
    pub what: String,
    /// The estimate.
    pub estimate: Seconds,
    /// The budget.
    pub budget: Seconds,
    /// `"set with `--max-time`"`, or the default and how to change it.
    pub set_by: &'static str,
    /// What to change.
    pub advice: String,
}

/// Refuses work estimated to take `seconds`, more than the time budget. `what` names the
/// work and the fields or flags it follows; `advice` says what to change.
pub fn check_time(
    seconds: f64,
    what: impl fmt::Display,
    advice: impl fmt::Display,
) -> Result<(), OverTime> {
    let budget = max_time().as_secs_f64();
    if seconds <= budget {
        return Ok(());
    }
    Err(OverTime {
        what: what.to_string(),
        estimate: Seconds(seconds),
        budget: Seconds(budget),
        set_by: match MAX_TIME_MS.load(Ordering::Relaxed) {
            0 => "the default; set another with `--max-time`",
            _ => "set with `--max-time`",
        },
        advice: advice.to_string(),
    })
}

/// Parses a length of time: seconds, or a number with `s`, `m` (minutes), `h` or `d`.
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let bad = || format!("expected a time like 90s, 10m, 2h or 1d; got {text:?}");
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let value: f64 = number.parse().map_err(|_| bad())?;
    let scale = match unit.trim() {
        "" | "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        "d" => 86_400.0,
        _ => return Err(bad()),
    };
    let seconds = value * scale;
    if seconds.is_finite() && (0.001..=1e12).contains(&seconds) {
        Ok(Duration::from_secs_f64(seconds))
    } else {
        Err(bad())
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
    use std::collections::HashMap;

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
    fn times_read_and_show() {
        assert_eq!(parse_duration("90s"), Ok(Duration::from_secs(90)));
        assert_eq!(parse_duration("10m"), Ok(Duration::from_secs(600)));
        assert_eq!(parse_duration("1.5h"), Ok(Duration::from_secs(5400)));
        assert_eq!(parse_duration("2d"), Ok(Duration::from_secs(172_800)));
        assert_eq!(parse_duration("45"), Ok(Duration::from_secs(45)));
        for bad in ["", "h", "-1h", "5w", "0", "1e400"] {
            assert!(parse_duration(bad).is_err(), "{bad}");
        }
        let shown = |s: f64| Seconds(s).to_string();
        assert_eq!(shown(2.25), "2.2 s");
        assert_eq!(shown(95.0), "95 s");
        assert_eq!(shown(330.0), "5.5 min");
        assert_eq!(shown(9000.0), "2.5 h");
        assert_eq!(shown(864_000.0), "10 days");
        assert_eq!(shown(1.767e10), "560 years");
        assert_eq!(shown(3.156e11), "1.0e4 years");
        assert_eq!(shown(f64::INFINITY), "forever");
    }

    #[test]
    fn work_over_the_time_budget_is_refused() {
        // The default budget (no test in this crate sets another).
        assert_eq!(max_time(), DEFAULT_MAX_TIME);
        assert!(check_time(3599.0, "x", "y").is_ok());
        let e = check_time(
            7200.0,
            "a breeding round of 9 plants",
            "lower `max_symbols`",
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "a breeding round of 9 plants would take up to about 2.0 h, more than the time \
             budget of 1.0 h (the default; set another with `--max-time`); lower \
             `max_symbols`"
        );
    }

    #[test]
    fn the_default_fits_the_machine() {
        let d = default_max_memory();
        assert!(d > 0);
        assert!(check(d, "all of it", "").is_ok());
        let e = check(d + 1, "a little more (`--count`)", "use fewer plants").unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("a little more (`--count`) would need about"),
            "{text}"
        );
        assert!(text.contains("--max-memory"), "{text}");
        assert!(text.ends_with("use fewer plants"), "{text}");
        assert_eq!(e.set_by, default_budget().source);
    }

    const LIMITS: &str = "\
Limit                     Soft Limit           Hard Limit           Units     
Max cpu time              unlimited            unlimited            seconds   
Max data size             unlimited            unlimited            bytes     
Max stack size            8388608              unlimited            bytes     
Max address space         unlimited            unlimited            bytes     
";

    #[test]
    fn proc_files_are_read() {
        assert_eq!(parse_rlimits(LIMITS), (None, None));
        let set = LIMITS
            .replace(
                "Max address space         unlimited            unlimited",
                "Max address space         4294967296           8589934592",
            )
            .replace(
                "Max data size             unlimited ",
                "Max data size             1073741824",
            );
        assert_eq!(parse_rlimits(&set), (Some(4 << 30), Some(1 << 30)));
        assert_eq!(parse_rlimits(""), (None, None));
        let status =
            "Name:\tsylva\nVmPeak:\t  300000 kB\nVmSize:\t  215000 kB\nVmData:\t   20480 kB\n";
        assert_eq!(parse_status(status), (Some(215_000 * 1024), Some(20 << 20)));
        assert_eq!(
            parse_meminfo("MemTotal:       24684084 kB\nMemFree: 1 kB\n"),
            Some(24_684_084 * 1024)
        );
        assert_eq!(parse_meminfo("MemFree: 1 kB\n"), None);
        assert_eq!(parse_cgroup_limit("max\n"), None);
        assert_eq!(parse_cgroup_limit("9223372036854771712\n"), None);
        assert_eq!(parse_cgroup_limit("2147483648\n"), Some(2 << 30));
        assert_eq!(parse_cgroup_limit("lots"), None);
    }

    #[test]
    fn the_least_limit_sets_the_budget() {
        let machine = Limits {
            machine: Some(24 << 30),
            ..Limits::default()
        };
        assert_eq!(
            machine.budget(),
            Budget {
                bytes: 12 << 30,
                source: Source::Machine { total: 24 << 30 }
            }
        );
        // A small machine still gets 1 GiB.
        let small = Limits {
            machine: Some(1 << 30),
            ..Limits::default()
        };
        assert_eq!(small.budget().bytes, 1 << 30);
        assert_eq!(Limits::default().budget().source, Source::Unknown);
        assert_eq!(Limits::default().budget().bytes, 4 << 30);

        let cgroup = Limits {
            cgroup: Some((2 << 30, PathBuf::from("/sys/fs/cgroup/ci/memory.max"))),
            ..machine.clone()
        };
        let b = cgroup.budget();
        assert_eq!(b.bytes, 1 << 30);
        assert!(matches!(b.source, Source::Cgroup { limit, .. } if limit == 2 << 30));

        // 4 GiB of address space of which 256 MiB are mapped: 1.875 GiB.
        let address_space = Limits {
            address_space: Some((4 << 30, 256 << 20)),
            ..machine.clone()
        };
        let b = address_space.budget();
        assert_eq!(b.bytes, (4 << 30) / 2 - (128 << 20));
        assert_eq!(
            b.source,
            Source::AddressSpace {
                limit: 4 << 30,
                used: 256 << 20
            }
        );
        // The cgroup wins again when it is the smaller.
        let both = Limits {
            cgroup: cgroup.cgroup.clone(),
            ..address_space.clone()
        };
        assert_eq!(both.budget(), cgroup.budget());

        let data = Limits {
            data: Some((1 << 30, 64 << 20)),
            ..address_space.clone()
        };
        assert_eq!(
            data.budget(),
            Budget {
                bytes: (1 << 29) - (32 << 20),
                source: Source::Data {
                    limit: 1 << 30,
                    used: 64 << 20
                }
            }
        );
        // A limit already spent gives a budget of nothing, not an overflow.
        let spent = Limits {
            address_space: Some((100 << 20, 200 << 20)),
            ..Limits::default()
        };
        assert_eq!(spent.budget().bytes, 0);
    }

    #[test]
    fn refusals_say_which_limit_set_the_budget() {
        let source = Source::AddressSpace {
            limit: 4 << 30,
            used: 200 << 20,
        };
        let e = OverBudget {
            what: "a garden of 100000 plants (`--count`)".into(),
            needed: Bytes(5 << 30),
            budget: Bytes(1_992_294_400),
            set_by: source,
            advice: "plant fewer".into(),
        };
        assert_eq!(
            e.to_string(),
            "a garden of 100000 plants (`--count`) would need about 5.0 GiB of memory, more \
             than the budget of 1.9 GiB (half of what the process's address-space limit \
             leaves: RLIMIT_AS 4.0 GiB, 200.0 MiB of it mapped at start; set another with \
             `--max-memory`); plant fewer"
        );
        let shown = |s: Source| s.to_string();
        assert_eq!(shown(Source::Set), "set with `--max-memory`");
        assert!(shown(Source::Machine { total: 8 << 30 }).contains("machine's memory of 8.0 GiB"));
        assert!(
            shown(Source::Cgroup {
                limit: 2 << 30,
                file: PathBuf::from("/sys/fs/cgroup/ci/memory.max")
            })
            .contains("cgroup's memory limit of 2.0 GiB in /sys/fs/cgroup/ci/memory.max")
        );
        assert!(
            shown(Source::Data {
                limit: 1 << 30,
                used: 1 << 20
            })
            .contains("RLIMIT_DATA 1.0 GiB")
        );
    }

    /// A reader over a few fake files.
    fn files(entries: &[(&str, &str)]) -> impl Fn(&Path) -> Option<String> {
        let map: HashMap<PathBuf, String> = entries
            .iter()
            .map(|(p, t)| (PathBuf::from(p), (*t).to_owned()))
            .collect();
        move |p: &Path| map.get(p).cloned()
    }

    const MOUNTS_V2: &str = "\
24 30 0:22 / /sys rw,nosuid,nodev,noexec,relatime shared:7 - sysfs sysfs rw
35 24 0:30 / /sys/fs/cgroup rw,nosuid,nodev,noexec,relatime shared:9 - cgroup2 cgroup2 rw,nsdelegate,memory_recursiveprot
";

    #[test]
    fn cgroup_v2_limits_bind_from_any_ancestor() {
        let cgroup = "0::/user.slice/user-1000.slice/session-2.scope\n";
        // The slice above the session holds the limit; the session has none.
        let read = files(&[
            (
                "/sys/fs/cgroup/user.slice/user-1000.slice/session-2.scope/memory.max",
                "max\n",
            ),
            (
                "/sys/fs/cgroup/user.slice/user-1000.slice/memory.max",
                "3221225472\n",
            ),
            ("/sys/fs/cgroup/user.slice/memory.max", "8589934592\n"),
        ]);
        assert_eq!(
            cgroup_limit(cgroup, MOUNTS_V2, &read),
            Some((
                3 << 30,
                PathBuf::from("/sys/fs/cgroup/user.slice/user-1000.slice/memory.max")
            ))
        );
        // No limit anywhere.
        let none = files(&[(
            "/sys/fs/cgroup/user.slice/user-1000.slice/session-2.scope/memory.max",
            "max\n",
        )]);
        assert_eq!(cgroup_limit(cgroup, MOUNTS_V2, &none), None);
        // Inside a container's cgroup namespace the process's cgroup is the mount's root.
        let container = files(&[("/sys/fs/cgroup/memory.max", "1073741824\n")]);
        assert_eq!(
            cgroup_limit("0::/\n", MOUNTS_V2, &container),
            Some((1 << 30, PathBuf::from("/sys/fs/cgroup/memory.max")))
        );
        // Without a cgroup2 mount nothing is read.
        assert_eq!(cgroup_limit(cgroup, "", &read), None);
        // A path that climbs out of the mount is ignored.
        assert_eq!(cgroup_limit("0::/../../x\n", MOUNTS_V2, &read), None);
    }

    #[test]
    fn cgroup_v1_limits_are_read_where_the_memory_controller_is() {
        // Hybrid hierarchy (v1 controllers and an empty unified tree), as on this kind of
        // host; a mount root that is not `/` (a container's own cgroup), and a mount point
        // with a space in it.
        let mounts = "\
35 31 0:32 /docker/abc /sys/fs/cgroup/mem\\040ory rw,relatime - cgroup cgroup rw,memory
36 31 0:33 / /sys/fs/cgroup/cpu rw,relatime - cgroup cgroup rw,cpu
41 31 0:38 / /sys/fs/cgroup/unified rw,relatime - cgroup2 cgroup2 rw
";
        let cgroup = "8:cpu:/\n4:memory:/docker/abc/job\n0::/\n";
        let read = files(&[
            (
                "/sys/fs/cgroup/mem ory/job/memory.limit_in_bytes",
                "9223372036854771712\n",
            ),
            (
                "/sys/fs/cgroup/mem ory/memory.limit_in_bytes",
                "536870912\n",
            ),
            // The unified tree's root has no memory.max.
        ]);
        assert_eq!(
            cgroup_limit(cgroup, mounts, &read),
            Some((
                512 << 20,
                PathBuf::from("/sys/fs/cgroup/mem ory/memory.limit_in_bytes")
            ))
        );
    }

    #[test]
    fn this_process_limits_are_read() {
        // Whatever this machine's limits are, the machine's memory is read on Linux and the
        // budget is no more than half of it (or the 1 GiB floor).
        let limits = Limits::read();
        if cfg!(target_os = "linux") {
            let total = limits.machine.expect("MemTotal is read");
            assert!(limits.budget().bytes <= (total / 2).max(GIB));
        }
    }
}
