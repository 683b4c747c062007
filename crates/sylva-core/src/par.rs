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

use std::sync::Arc;

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
        match self {
            Pool::Serial => (0..jobs).map(job).collect(),
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
        match self {
            Pool::Serial => {
                let mut state = init();
                (0..jobs).map(|i| job(&mut state, i)).collect()
            }
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
        match self {
            Pool::Serial => items.iter_mut().map(job).collect(),
            Pool::Parallel(pool) => pool.install(|| items.par_iter_mut().map(job).collect()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
