//! The rayon thread pool every parallel command runs on.

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
