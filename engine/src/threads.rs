//! How many threads a call may ask for, and running work on that many.

use crate::error::{bail, EngineError};

/// Threads per core a call may ask for (as `spll_hw.limits`): more only adds scheduling
/// overhead, and thousands would take seconds to start.
pub const THREADS_PER_CORE: usize = 8;

/// Largest `threads` a call accepts: [`THREADS_PER_CORE`] per core this process may use.
pub fn max_threads() -> usize {
    THREADS_PER_CORE * std::thread::available_parallelism().map_or(1, usize::from)
}

/// Run `work` on a pool of `threads` threads (rayon's global pool when `None`). A count of 0 or
/// above [`max_threads`] is an error, and no thread is started for it.
pub fn install<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> T + Send,
) -> Result<T, EngineError> {
    let Some(n) = threads else {
        return Ok(work());
    };
    if n == 0 {
        bail!("threads must be >= 1");
    }
    let limit = max_threads();
    if n > limit {
        bail!(
            "threads = {n} is more than this machine can use: at most {limit} \
             ({THREADS_PER_CORE} per core) are accepted"
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| EngineError(format!("cannot start {n} threads: {e}")))?;
    Ok(pool.install(work))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_beyond_the_cap_are_refused_before_any_thread_starts() {
        assert_eq!(install(Some(2), || 7).unwrap(), 7);
        assert_eq!(install(None, || 8).unwrap(), 8);
        assert!(install(Some(0), || ()).unwrap_err().0.contains(">= 1"));
        let err = install(Some(max_threads() + 1), || ()).unwrap_err().0;
        assert!(err.contains("more than this machine can use"), "{err}");
    }
}
