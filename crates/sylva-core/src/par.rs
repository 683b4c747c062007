//! The one seam where work goes parallel.
//!
//! A [`Pool`] runs jobs serially or on a dedicated rayon pool of a chosen size, and always
//! returns results in job order, so an outcome never depends on the number of threads. The
//! evolution engine evaluates through it, L-system gardens grow their plants through it and
//! contact sheets render their cells through it; the command line builds one from
//! `--threads`.
//!
//! ```
//! use sylva_core::par::Pool;
//!
//! let squares = Pool::with_threads(2)?.map(5, |i| i * i);
//! assert_eq!(squares, Pool::Serial.map(5, |i| i * i));
//! assert_eq!(squares, vec![0, 1, 4, 9, 16]);
//! # Ok::<(), rayon::ThreadPoolBuildError>(())
//! ```
//!
//! Long work (a generation of a large population) can be cut short between jobs: under
//! [`Stop::watch`], every job of every map made from the watching thread first checks the
//! [`Stop`], so a front end's Ctrl-C ends the work within one job rather than one generation.

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use rayon::prelude::*;

pub use rayon::ThreadPoolBuildError;

/// Where parallel work runs.
#[derive(Clone, Debug, Default)]
pub enum Pool {
    /// On the calling thread.
    #[default]
    Serial,
    /// On a dedicated rayon pool.
    Parallel(Arc<rayon::ThreadPool>),
}

impl Pool {
    /// A pool of `threads` threads; 0 means one per core, 1 means serial.
    pub fn with_threads(threads: usize) -> Result<Pool, ThreadPoolBuildError> {
        if threads == 1 {
            return Ok(Pool::Serial);
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("sylva-{i}"))
            .build()?;
        Ok(Pool::Parallel(Arc::new(pool)))
    }

    /// Number of threads used.
    pub fn threads(&self) -> usize {
        match self {
            Pool::Serial => 1,
            Pool::Parallel(pool) => pool.current_num_threads(),
        }
    }

    /// `(0..jobs).map(job)`, in order.
    pub fn map<T, F>(&self, jobs: usize, job: F) -> Vec<T>
    where
        T: Send,
        F: Fn(usize) -> T + Sync + Send,
    {
        let stop = watched();
        let job = |i| {
            check(stop.as_ref());
            job(i)
        };
        match self {
            Pool::Serial => (0..jobs).map(job).collect(),
            // Watched, the first job to stop halts the others: without the fuse, every job
            // left would start, and unwind, in turn.
            Pool::Parallel(pool) if stop.is_some() => {
                pool.install(|| (0..jobs).into_par_iter().panic_fuse().map(job).collect())
            }
            Pool::Parallel(pool) => pool.install(|| (0..jobs).into_par_iter().map(job).collect()),
        }
    }

    /// `(0..jobs).map(job)`, in order, where each thread first makes its own scratch state
    /// with `init` (a renderer, a buffer) and reuses it for the jobs it runs.
    pub fn map_init<S, T, I, F>(&self, jobs: usize, init: I, job: F) -> Vec<T>
    where
        T: Send,
        I: Fn() -> S + Sync + Send,
        F: Fn(&mut S, usize) -> T + Sync + Send,
    {
        let stop = watched();
        let job = |state: &mut S, i| {
            check(stop.as_ref());
            job(state, i)
        };
        match self {
            Pool::Serial => {
                let mut state = init();
                (0..jobs).map(|i| job(&mut state, i)).collect()
            }
            Pool::Parallel(pool) if stop.is_some() => pool.install(|| {
                (0..jobs)
                    .into_par_iter()
                    .panic_fuse()
                    .map_init(init, job)
                    .collect()
            }),
            Pool::Parallel(pool) => {
                pool.install(|| (0..jobs).into_par_iter().map_init(init, job).collect())
            }
        }
    }

    /// `items.iter_mut().map(job)`, in order.
    pub fn map_mut<T, U, F>(&self, items: &mut [T], job: F) -> Vec<U>
    where
        T: Send,
        U: Send,
        F: Fn(&mut T) -> U + Sync + Send,
    {
        let stop = watched();
        let job = |item: &mut T| {
            check(stop.as_ref());
            job(item)
        };
        match self {
            Pool::Serial => items.iter_mut().map(job).collect(),
            Pool::Parallel(pool) if stop.is_some() => {
                pool.install(|| items.par_iter_mut().panic_fuse().map(job).collect())
            }
            Pool::Parallel(pool) => pool.install(|| items.par_iter_mut().map(job).collect()),
        }
    }
}

/// A flag that cuts work short between jobs ([`Stop::watch`]); clones share it, so a front
/// end keeps one and sets it from another thread (on Ctrl-C). It may also carry a deadline
/// ([`Stop::stop_at`]), after which it counts as set: a run given so many seconds ends on
/// time however long its steps are.
#[derive(Clone, Debug, Default)]
pub struct Stop(Arc<StopState>);

#[derive(Debug)]
struct StopState {
    set: AtomicBool,
    /// When the stop was made: deadlines are kept as nanoseconds after it.
    made: Instant,
    /// Nanoseconds after `made` at which the stop counts as set; `u64::MAX`: never.
    deadline: AtomicU64,
}

impl Default for StopState {
    fn default() -> Self {
        StopState {
            set: AtomicBool::new(false),
            made: Instant::now(),
            deadline: AtomicU64::new(u64::MAX),
        }
    }
}

/// Work ended by its [`Stop`] before it finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("stopped before it finished")]
pub struct Stopped;

thread_local! {
    /// The stop watched by the work running on this thread, if any ([`Stop::watch`]).
    static WATCHED: RefCell<Option<Stop>> = const { RefCell::new(None) };
}

/// The stop the calling thread's work is watched by, for a map's jobs to check (they may run
/// on other threads).
fn watched() -> Option<Stop> {
    WATCHED.with(|w| w.borrow().clone())
}

/// Ends the work under way here if the [`Stop`] it is watched by is set, as a [`Pool`] map's
/// jobs do: for a long loop that runs outside a map on the watching thread (a model making a
/// large first generation). Does nothing for unwatched work.
pub fn stop_point() {
    check(watched().as_ref());
}

/// Ends the job under way if its stop is set: the job unwinds, without the panic hook (no
/// message is printed), to [`Stop::watch`], which returns [`Stopped`].
fn check(stop: Option<&Stop>) {
    if stop.is_some_and(Stop::is_stopped) {
        std::panic::resume_unwind(Box::new(Stopped));
    }
}

impl Stop {
    /// A flag, not set.
    pub fn new() -> Stop {
        Stop::default()
    }

    /// Sets the flag: watched work ends at its next job.
    pub fn stop(&self) {
        self.0.set.store(true, Ordering::Relaxed);
    }

    /// Whether the flag is set or the deadline has passed.
    pub fn is_stopped(&self) -> bool {
        self.is_set() || self.timed_out()
    }

    /// Whether the flag is set ([`Stop::stop`]), deadline aside.
    pub fn is_set(&self) -> bool {
        self.0.set.load(Ordering::Relaxed)
    }

    /// Whether the deadline ([`Stop::stop_at`]) has passed.
    pub fn timed_out(&self) -> bool {
        let deadline = self.0.deadline.load(Ordering::Relaxed);
        deadline != u64::MAX && self.0.made.elapsed().as_nanos() >= u128::from(deadline)
    }

    /// Makes the stop count as set from `deadline` on (`None`: no deadline, the default).
    pub fn stop_at(&self, deadline: Option<Instant>) {
        let nanos = deadline.map_or(u64::MAX, |d| {
            let after = d.saturating_duration_since(self.0.made).as_nanos();
            u64::try_from(after)
                .unwrap_or(u64::MAX - 1)
                .min(u64::MAX - 1)
        });
        self.0.deadline.store(nanos, Ordering::Relaxed);
    }

    /// Clears the flag, for the next piece of work (the deadline stays).
    pub fn reset(&self) {
        self.0.set.store(false, Ordering::Relaxed);
    }

    /// Runs `work` on this thread so that every job of every [`Pool`] map it makes from this
    /// thread (on whichever thread the job runs) first checks this flag, and once it is set
    /// ends there. Returns `Err(Stopped)` if the work was cut short: whatever it was changing
    /// may be half changed, so the caller throws that away or puts it back as it was. Jobs
    /// under way finish; maps made from a pool's own threads (maps within a job) are not
    /// watched. A panic that is not a stop goes on as a panic.
    pub fn watch<T>(&self, work: impl FnOnce() -> T) -> Result<T, Stopped> {
        let outer = WATCHED.with(|w| w.replace(Some(self.clone())));
        // Unwinding is the one way out of a map that is not ours to change (the evolution
        // engine's); `Stopped` is its only payload here, and the caller restores any state.
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work));
        WATCHED.with(|w| *w.borrow_mut() = outer);
        match result {
            Ok(value) => Ok(value),
            Err(payload) if payload.is::<Stopped>() => Err(Stopped),
            Err(payload) => std::panic::resume_unwind(payload),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stop_point_ends_watched_loops_only() {
        let stop = Stop::new();
        let mut done = 0;
        let result = stop.watch(|| {
            for i in 0..100 {
                if i == 10 {
                    stop.stop();
                }
                stop_point();
                done += 1;
            }
        });
        assert_eq!((result, done), (Err(Stopped), 10));
        // Outside watched work it does nothing, set or not.
        stop_point();
    }

    #[test]
    fn a_stop_ends_watched_maps_between_jobs() {
        for pool in [Pool::Serial, Pool::with_threads(2).unwrap()] {
            let stop = Stop::new();
            let ran = std::sync::atomic::AtomicUsize::new(0);
            let result = stop.watch(|| {
                pool.map(10_000, |i| {
                    if ran.fetch_add(1, Ordering::Relaxed) == 10 {
                        stop.stop();
                    }
                    i
                })
            });
            assert_eq!(result, Err(Stopped));
            // The jobs under way when it was set finish; no other starts.
            assert!(
                ran.load(Ordering::Relaxed) < 100,
                "{}",
                ran.load(Ordering::Relaxed)
            );
            // Unwatched work, and watched work once the flag is cleared, run whole.
            assert_eq!(pool.map(3, |i| i), [0, 1, 2]);
            stop.reset();
            assert_eq!(stop.watch(|| pool.map(3, |i| i)), Ok(vec![0, 1, 2]));
            let mut items = [1, 2, 3];
            stop.stop();
            assert_eq!(
                stop.watch(|| pool.map_mut(&mut items, |x| *x)),
                Err(Stopped)
            );
            assert_eq!(
                stop.watch(|| pool.map_init(3, || 0, |_, i| i)),
                Err(Stopped)
            );
            // Outside a map, the flag does nothing.
            assert_eq!(stop.watch(|| 7), Ok(7));
        }
    }

    #[test]
    fn a_deadline_passed_stops_and_none_clears_it() {
        let stop = Stop::new();
        stop.stop_at(Some(Instant::now() + std::time::Duration::from_secs(3600)));
        assert!(!stop.is_stopped() && !stop.timed_out());
        assert_eq!(stop.watch(|| Pool::Serial.map(3, |i| i)), Ok(vec![0, 1, 2]));
        stop.stop_at(Some(Instant::now()));
        assert!(stop.is_stopped() && stop.timed_out());
        assert_eq!(stop.watch(|| Pool::Serial.map(3, |i| i)), Err(Stopped));
        // A deadline before the stop was made has passed too; reset leaves it.
        stop.reset();
        let before = Instant::now().checked_sub(std::time::Duration::from_secs(1));
        stop.stop_at(Some(before.unwrap_or_else(Instant::now)));
        assert!(stop.timed_out());
        stop.stop_at(None);
        assert!(!stop.is_stopped());
        // A clone shares the deadline; the flag alone is not a timeout.
        let clone = stop.clone();
        clone.stop();
        assert!(stop.is_stopped() && !stop.timed_out());
    }

    #[test]
    fn a_panic_is_not_a_stop() {
        let stop = Stop::new();
        let caught =
            std::panic::catch_unwind(|| stop.watch(|| Pool::Serial.map(1, |_| panic!("bug"))));
        assert!(caught.is_err());
    }

    #[test]
    fn every_pool_gives_the_same_order() {
        let pools = [
            Pool::Serial,
            Pool::with_threads(2).unwrap(),
            Pool::with_threads(0).unwrap(),
        ];
        for pool in &pools {
            assert_eq!(
                pool.map(100, |i| i * 3),
                (0..100).map(|i| i * 3).collect::<Vec<_>>()
            );
            let counted = pool.map_init(
                10,
                || 0usize,
                |n, i| {
                    *n += 1;
                    i + 100 * usize::from(*n == 0)
                },
            );
            assert_eq!(counted, (0..10).collect::<Vec<_>>());
            let mut items: Vec<u32> = (0..50).collect();
            let doubled = pool.map_mut(&mut items, |x| {
                *x *= 2;
                *x + 1
            });
            assert_eq!(items, (0..50).map(|x| x * 2).collect::<Vec<_>>());
            assert_eq!(doubled, (0..50).map(|x| x * 2 + 1).collect::<Vec<_>>());
        }
        assert_eq!(pools[0].threads(), 1);
        assert_eq!(pools[1].threads(), 2);
    }
}
