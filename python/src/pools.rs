//! Rayon pools of a chosen size for the calls that take `threads`. A sweep's worker processes
//! share the machine's cores: each running rayon's global pool (one thread per core) puts
//! workers × cores threads on the cores, which then preempt one another mid-render. A call given
//! `threads` runs on a pool of that many threads instead, kept for the process's later calls of
//! the same size. A render's images do not depend on its thread count (python/tests).

use crate::errors::bad_argument;
use pyo3::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// The process's pools by size.
fn pools() -> &'static Mutex<HashMap<usize, Arc<ThreadPool>>> {
    static POOLS: OnceLock<Mutex<HashMap<usize, Arc<ThreadPool>>>> = OnceLock::new();
    POOLS.get_or_init(|| Mutex::new(HashMap::new()))
}

/// The pool of `threads` threads, built on first use.
fn pool(threads: usize) -> PyResult<Arc<ThreadPool>> {
    let mut pools = pools()
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some(pool) = pools.get(&threads) {
        return Ok(Arc::clone(pool));
    }
    let pool = ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(move |i| format!("irpol-{threads}-{i}"))
        .build()
        .map_err(|e| bad_argument(format!("cannot start {threads} threads: {e}")))?;
    let pool = Arc::new(pool);
    pools.insert(threads, Arc::clone(&pool));
    Ok(pool)
}

/// Runs `work` without the GIL: on rayon's global pool for `threads` None, else on a pool of
/// that many threads (at least 1).
pub(crate) fn detached_on<R: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    work: impl FnOnce() -> R + Send,
) -> PyResult<R> {
    match threads {
        None => Ok(py.detach(work)),
        Some(0) => Err(bad_argument("threads must be at least 1")),
        Some(n) => {
            let pool = pool(n)?;
            Ok(py.detach(|| pool.install(work)))
        }
    }
}
