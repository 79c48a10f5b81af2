//! The rayon thread pool every parallel command runs on.

/// The most worker threads a command or a Python call takes (`--threads`'s range).
pub const MAX_THREADS: usize = 4096;

/// The thread count rayon's default pool would take from the environment when it is above
/// [`MAX_THREADS`] (99 999 threads ran out of memory before any work), in words naming the
/// variable, its value and the range; `None` otherwise. The variables are read as rayon reads
/// them: the first of `RAYON_NUM_THREADS` and the older `RAYON_RS_NUM_CPUS` that holds a whole
/// number above 0 counts (untrimmed; other values are ignored).
pub fn env_threads_beyond_range() -> Option<String> {
    for var in ["RAYON_NUM_THREADS", "RAYON_RS_NUM_CPUS"] {
        match std::env::var(var)
            .ok()
            .and_then(|t| t.parse::<usize>().ok())
        {
            Some(n) if n > MAX_THREADS => {
                return Some(format!(
                    "{var} = {n}: allowed [1, {MAX_THREADS}] (0 or unset: one per core)"
                ))
            }
            Some(n) if n > 0 => return None,
            _ => {}
        }
    }
    None
}

/// A rayon thread pool of `threads` workers (`None`: rayon's default, which honours
/// `RAYON_NUM_THREADS` and otherwise uses one worker per core). Callers map the error into
/// their own error type.
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool, rayon::ThreadPoolBuildError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n);
    }
    builder.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_thread_count_is_the_one_asked_for() {
        assert_eq!(pool(Some(3)).unwrap().current_num_threads(), 3);
        assert!(pool(None).unwrap().current_num_threads() >= 1);
    }
}
