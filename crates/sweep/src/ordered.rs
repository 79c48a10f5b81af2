//! Work stealing over numbered jobs, with an ordered writer.
//!
//! [`run_ordered`] runs `work(i)` for every position `i` in `0..n` on the threads of a rayon
//! pool and hands the results to an [`OrderedSink`] on the calling thread, the writer, in
//! position order, whatever order they complete in and whatever the thread count.
//!
//! - **Work stealing**: each worker takes the next position from a shared counter when it is
//!   free, so a slow job holds up only the thread running it; there is no barrier between
//!   groups of jobs.
//! - **Ordered writer**: workers send `(position, result)` over a channel; the writer keeps
//!   the results that arrive early in a reorder buffer (a `BTreeMap` keyed by position) and
//!   gives the sink every contiguous run as soon as the run's first position is done.
//! - **The bound**: a worker takes position `i` only while `i < written + window`, where
//!   `written` counts the results the sink has taken. So at most `window` results are done
//!   and waiting at any time, however slow one job is: memory stays bounded, and a stopped
//!   run loses at most the jobs in flight plus those waiting in the buffer.
//! - **Stopping**: a sink error stops the workers taking new positions (the jobs in flight
//!   finish, their results are dropped) and is returned; a panic in a job stops them too and
//!   is re-raised once every worker has returned.
//!
//! The writer is the calling thread, not a pool thread, so the sink's I/O (a `sync_data`
//! that waits on the disk) never holds up a drop. Called from a thread of the pool itself,
//! [`run_ordered`] runs the jobs one after another on that thread instead (blocking there as
//! the writer would take one of the pool's threads, and with a pool of one wait forever).

use std::collections::BTreeMap;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Duration;

/// What takes the results of [`run_ordered`], in position order, on the calling thread.
pub trait OrderedSink<T> {
    /// Why the sink could not take a result (the run stops).
    type Error;

    /// Takes the results of positions `first`, `first + 1`, ... (`items` in that order, never
    /// empty). Every position reaches the sink exactly once, in increasing order.
    fn take(&mut self, first: usize, items: Vec<T>) -> Result<(), Self::Error>;

    /// How long the writer may wait for the next result before calling [`Self::idle`];
    /// `None` (the default): as long as it takes.
    fn wait_limit(&self) -> Option<Duration> {
        None
    }

    /// Called when [`Self::wait_limit`] passed with no result arriving (e.g. to sync what was
    /// written while a slow job runs).
    fn idle(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// What a run of [`run_ordered`] looked like (for tests and diagnostics).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OrderedStats {
    /// Worker threads used.
    pub workers: usize,
    /// The window used (at least the number of workers).
    pub window: usize,
    /// The most results that were done and waiting in the reorder buffer at once (at most
    /// `window`).
    pub max_buffered: usize,
}

/// The counter workers take positions from, and how far the writer has got.
struct Gate {
    /// The next position not yet taken.
    next: usize,
    /// Positions the sink has taken (all of `0..written`).
    written: usize,
    /// Take nothing more.
    stop: bool,
}

struct Shared {
    gate: Mutex<Gate>,
    /// Signalled when `written` or `stop` changes.
    moved: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Gate> {
        self.gate.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The next position to run, waiting while it is `window` or more ahead of the writer;
    /// `None` when every position is taken or the run stops.
    fn take(&self, n: usize, window: usize) -> Option<usize> {
        let mut g = self.lock();
        loop {
            if g.stop || g.next >= n {
                return None;
            }
            if g.next < g.written + window {
                g.next += 1;
                return Some(g.next - 1);
            }
            g = self.moved.wait(g).unwrap_or_else(|e| e.into_inner());
        }
    }

    fn advance(&self, written: usize) {
        self.lock().written = written;
        self.moved.notify_all();
    }

    fn stop(&self) {
        self.lock().stop = true;
        self.moved.notify_all();
    }
}

/// Stops the run when a worker unwinds (a panic in a job), so the others do not wait for a
/// result that will never come.
struct StopOnPanic<'a>(&'a Shared);

impl Drop for StopOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.stop();
        }
    }
}

/// Runs `work(i)` for every `i` in `0..n` on `pool`'s threads and gives the results to
/// `sink` in order of `i` (see the module doc). `window` bounds how far workers may run ahead
/// of the writer (raised to the number of workers if smaller). Returns the sink's first
/// error, if any; a panic in `work` is re-raised after every worker has returned.
pub fn run_ordered<T, W, S>(
    pool: &rayon::ThreadPool,
    n: usize,
    window: usize,
    work: W,
    sink: &mut S,
) -> Result<OrderedStats, S::Error>
where
    T: Send,
    W: Fn(usize) -> T + Sync,
    S: OrderedSink<T>,
{
    if n == 0 {
        return Ok(OrderedStats::default());
    }
    if pool.current_thread_index().is_some() {
        for i in 0..n {
            sink.take(i, vec![work(i)])?;
        }
        return Ok(OrderedStats {
            workers: 1,
            window: 1,
            max_buffered: 1,
        });
    }
    let workers = pool.current_num_threads().clamp(1, n);
    let window = window.max(workers);
    let shared = Shared {
        gate: Mutex::new(Gate {
            next: 0,
            written: 0,
            stop: false,
        }),
        moved: Condvar::new(),
    };
    let (tx, rx) = mpsc::channel::<(usize, T)>();
    let mut stats = OrderedStats {
        workers,
        window,
        max_buffered: 0,
    };
    pool.in_place_scope(|scope| {
        for _ in 0..workers {
            let tx = tx.clone();
            let (shared, work) = (&shared, &work);
            scope.spawn(move |_| {
                let _guard = StopOnPanic(shared);
                while let Some(i) = shared.take(n, window) {
                    if tx.send((i, work(i))).is_err() {
                        break;
                    }
                }
            });
        }
        // The workers hold the only senders now: when they have all returned (a panic
        // included), `recv` says so instead of waiting.
        drop(tx);
        let r = write_in_order(&rx, &shared, n, sink, &mut stats);
        shared.stop();
        r
    })?;
    Ok(stats)
}

/// The writer: receives results, buffers those that come early, and gives the sink every
/// contiguous run.
fn write_in_order<T, S: OrderedSink<T>>(
    rx: &mpsc::Receiver<(usize, T)>,
    shared: &Shared,
    n: usize,
    sink: &mut S,
    stats: &mut OrderedStats,
) -> Result<(), S::Error> {
    let mut buffer: BTreeMap<usize, T> = BTreeMap::new();
    let mut next = 0;
    while next < n {
        let got = match sink.wait_limit() {
            None => rx.recv().ok(),
            Some(limit) => match rx.recv_timeout(limit) {
                Ok(x) => Some(x),
                Err(RecvTimeoutError::Timeout) => {
                    sink.idle()?;
                    continue;
                }
                Err(RecvTimeoutError::Disconnected) => None,
            },
        };
        // Every worker returned with positions missing: a job panicked, and the scope
        // re-raises the panic.
        let Some((i, t)) = got else {
            return Ok(());
        };
        buffer.insert(i, t);
        stats.max_buffered = stats.max_buffered.max(buffer.len());
        let first = next;
        let mut run = Vec::new();
        while let Some(t) = buffer.remove(&next) {
            run.push(t);
            next += 1;
        }
        if !run.is_empty() {
            sink.take(first, run)?;
            shared.advance(next);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;

    fn pool(threads: usize) -> rayon::ThreadPool {
        crate::pool::pool(Some(threads)).unwrap()
    }

    /// Collects what it is given, checking order; fails at position `fail_at`.
    #[derive(Default)]
    struct Collect {
        seen: Vec<(usize, u64)>,
        taken: Arc<AtomicUsize>,
        fail_at: Option<usize>,
    }

    impl OrderedSink<u64> for Collect {
        type Error = String;
        fn take(&mut self, first: usize, items: Vec<u64>) -> Result<(), String> {
            assert!(!items.is_empty());
            assert_eq!(first, self.seen.len(), "runs are contiguous and in order");
            for (k, v) in items.into_iter().enumerate() {
                if Some(first + k) == self.fail_at {
                    return Err(format!("refused {}", first + k));
                }
                self.seen.push((first + k, v));
                self.taken.fetch_add(1, Ordering::SeqCst);
            }
            Ok(())
        }
    }

    /// A job whose cost varies a lot with its position (a pure function of it).
    fn uneven(i: usize) -> u64 {
        let spins = [1, 200_000, 3, 50_000, 7, 1, 400_000, 10][i % 8];
        let mut x = i as u64;
        for _ in 0..spins {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
        }
        x
    }

    #[test]
    fn results_reach_the_sink_in_order_for_any_thread_count() {
        let want: Vec<(usize, u64)> = (0..200).map(|i| (i, uneven(i))).collect();
        for threads in [1, 2, 3, 4] {
            for window in [1, 2, 16] {
                let mut sink = Collect::default();
                let stats = run_ordered(&pool(threads), 200, window, uneven, &mut sink).unwrap();
                assert_eq!(sink.seen, want, "{threads} threads, window {window}");
                assert_eq!(stats.workers, threads);
                assert!(stats.max_buffered <= stats.window, "{stats:?}");
            }
        }
        let mut sink = Collect::default();
        assert_eq!(
            run_ordered(&pool(2), 0, 4, uneven, &mut sink),
            Ok(OrderedStats::default())
        );
        assert!(sink.seen.is_empty());
    }

    #[test]
    fn workers_never_run_further_ahead_of_the_writer_than_the_window() {
        // Position 0 is held until positions 1..WINDOW are all done: the window is then full,
        // and a worker that took position WINDOW or later before 0 was written would break
        // the check in `work`.
        const WINDOW: usize = 8;
        let finished = AtomicUsize::new(0);
        let mut sink = Collect::default();
        let taken = Arc::clone(&sink.taken);
        let work = |i: usize| {
            assert!(
                i < taken.load(Ordering::SeqCst) + WINDOW,
                "position {i} taken with {} written",
                taken.load(Ordering::SeqCst)
            );
            if i == 0 {
                while finished.load(Ordering::SeqCst) < WINDOW - 1 {
                    std::thread::yield_now();
                }
            } else {
                finished.fetch_add(1, Ordering::SeqCst);
            }
            i as u64
        };
        let stats = run_ordered(&pool(4), 100, WINDOW, work, &mut sink).unwrap();
        assert_eq!(sink.seen.len(), 100);
        assert_eq!(stats.window, WINDOW);
        // 1..WINDOW waited in the buffer, then 0 came: the buffer was exactly full.
        assert_eq!(stats.max_buffered, WINDOW);
    }

    #[test]
    fn a_sink_error_stops_the_workers_and_is_returned() {
        let calls = AtomicUsize::new(0);
        let mut sink = Collect {
            fail_at: Some(5),
            ..Default::default()
        };
        let work = |i: usize| {
            calls.fetch_add(1, Ordering::SeqCst);
            uneven(i)
        };
        let r = run_ordered(&pool(2), 10_000, 4, work, &mut sink);
        assert_eq!(r, Err("refused 5".to_string()));
        assert_eq!(sink.seen.len(), 5);
        // Positions taken: at most those below 5 + the window, and the jobs then in flight.
        assert!(calls.load(Ordering::SeqCst) <= 5 + 4 + 2, "{calls:?}");
    }

    #[test]
    fn a_panicking_job_is_re_raised_not_waited_for() {
        let mut sink = Collect::default();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            run_ordered(
                &pool(2),
                1000,
                4,
                |i| {
                    assert!(i != 3, "job 3 fails");
                    i as u64
                },
                &mut sink,
            )
        }));
        assert!(r.is_err());
        assert!(sink.seen.len() <= 3);
    }

    #[test]
    fn called_from_inside_the_pool_it_runs_in_order_on_that_thread() {
        let p = pool(1);
        let seen = p.install(|| {
            let mut sink = Collect::default();
            run_ordered(&p, 50, 4, uneven, &mut sink).unwrap();
            sink.seen
        });
        assert_eq!(seen, (0..50).map(|i| (i, uneven(i))).collect::<Vec<_>>());
    }
}
