//! Made in parallel, consumed in order, with no barrier between batches and no thread of
//! its own for consuming: every thread of the current rayon pool takes the next index as
//! soon as it is done with one, into a ring of reused slots, and whichever thread finds
//! the next index in order made consumes it (and every made one after it), while the
//! others go on making. A worker waits only when the ring is full (the consumer is
//! behind by `ring` indices).
//!
//! Why no consuming thread: with one, two workers and the consumer share two cores, and
//! every hand-over is a wake-up, a context switch and a contended lock (about 9% of the
//! workers' time on two cores). Here a hand-over is a few atomic operations, and a pool
//! of T threads runs on T cores, the consuming included.
//!
//! The hand-over without a lock: a slot's `ready` holds the index made into it (plus one),
//! `consumed` the next index to consume, and the consumer's role is a flag taken with a
//! compare-and-swap. A worker that made an index and cannot take the role leaves it to the
//! thread holding it, which looks once more after letting go. Every store and load of
//! the three is sequentially consistent: of a worker's "made, then try the role" and the
//! holder's "let go, then look", one sees the other.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering::SeqCst};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};

/// Where the workers meet.
struct Ring<S, R, C, E> {
    slots: Vec<Mutex<Slot<S, R>>>,
    /// Per slot: the index made into it, plus one (0: none yet).
    ready: Vec<AtomicU64>,
    /// The next index to take.
    next: AtomicU64,
    /// The next index to consume; every index before it is consumed.
    consumed: AtomicU64,
    /// A thread is consuming.
    consuming: AtomicBool,
    /// The consumer, with the first error it gave.
    consumer: Mutex<(C, Option<E>)>,
    /// Stop taking indices: the consumer failed, or a worker panicked.
    stopped: AtomicBool,
    /// Workers waiting for a free slot, and what they wait on.
    waiting: AtomicUsize,
    waits: Mutex<()>,
    freed: Condvar,
    ring: u64,
    end: u64,
}

struct Slot<S, R> {
    buffers: S,
    result: Option<R>,
}

/// Lock, ignoring poisoning: a panic on one side is reported by the scope that joins it,
/// and the data is whole between statements.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Stops the others when a worker unwinds, so that none waits for the index it was making
/// or for the consumer's role it held (the panic itself goes on to the caller).
struct PanicGuard<'a, S, R, C, E>(&'a Ring<S, R, C, E>);

impl<S, R, C, E> Drop for PanicGuard<'_, S, R, C, E> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.stop();
        }
    }
}

impl<S, R, C, E> Ring<S, R, C, E> {
    /// No more indices are taken; waiting workers go.
    fn stop(&self) {
        self.stopped.store(true, SeqCst);
        let _g = lock(&self.waits);
        self.freed.notify_all();
    }
}

impl<S, R, C, E> Ring<S, R, C, E>
where
    C: FnMut(u64, &S, R) -> Result<(), E>,
{
    fn at(&self, i: u64) -> usize {
        (i % self.ring) as usize
    }

    fn is_made(&self, i: u64) -> bool {
        self.ready[self.at(i)].load(SeqCst) == i + 1
    }

    /// Consumes the made indices in order from `consumed` on, unless another thread is
    /// (which then looks again after letting go).
    fn consume_made(&self) {
        loop {
            if self
                .consuming
                .compare_exchange(false, true, SeqCst, SeqCst)
                .is_err()
            {
                return;
            }
            {
                let mut consumer = lock(&self.consumer);
                let (consume, error) = &mut *consumer;
                let mut k = self.consumed.load(SeqCst);
                while k < self.end && error.is_none() && self.is_made(k) {
                    let mut slot = lock(&self.slots[self.at(k)]);
                    let result = slot
                        .result
                        .take()
                        .expect("a slot holds its result from the moment it is marked made");
                    let outcome = consume(k, &slot.buffers, result);
                    drop(slot);
                    if let Err(e) = outcome {
                        *error = Some(e);
                        self.stop();
                        break;
                    }
                    k += 1;
                    self.consumed.store(k, SeqCst);
                    if self.waiting.load(SeqCst) > 0 {
                        let _g = lock(&self.waits);
                        self.freed.notify_all();
                    }
                }
            }
            // The window the look below is for: a worker that makes index `k` now finds
            // the role taken. Tests widen it.
            #[cfg(test)]
            std::thread::sleep(std::time::Duration::from_micros(20));
            self.consuming.store(false, SeqCst);
            let k = self.consumed.load(SeqCst);
            if self.stopped.load(SeqCst) || k >= self.end || !self.is_made(k) {
                return;
            }
        }
    }

    /// Waits until index `i`'s slot is free (the consumer is done with `i - ring`), or
    /// the run stopped: whether to go on.
    fn wait_for_slot(&self, i: u64) -> bool {
        let free =
            |r: &Self| r.stopped.load(SeqCst) || i < r.consumed.load(SeqCst).saturating_add(r.ring);
        if !free(self) {
            let mut g = lock(&self.waits);
            self.waiting.fetch_add(1, SeqCst);
            while !free(self) {
                g = self.freed.wait(g).unwrap_or_else(PoisonError::into_inner);
            }
            self.waiting.fetch_sub(1, SeqCst);
        }
        !self.stopped.load(SeqCst)
    }
}

/// Makes every index of `range` with `make` on all threads of the current rayon pool and
/// hands each result, in index order, to `consume`, which runs on whichever of those
/// threads finds the next index made (never on two at once). `make` fills the reused
/// buffers of its slot (`ring` slots, each `S::default()` at first) and gives its result;
/// `consume` sees the slot's buffers and the result. So at most `ring` results exist at
/// once however long the range, and a buffer is reused rather than allocated per index.
/// An error from `consume` stops the workers and is returned: indices being made then are
/// finished but not consumed, and no other is made. A panic in either goes on to the
/// caller.
///
/// Called from inside a rayon pool (`ThreadPool::install`), it uses that pool's threads;
/// otherwise rayon's global pool.
///
/// ```
/// let mut lines = Vec::new();
/// mjcf_forge::output::for_each_ordered(
///     0..1_000,
///     16,
///     |i, text: &mut String| {
///         text.clear();
///         text.push_str(&format!("line {i}"));
///         i % 7
///     },
///     |i, text, rest| {
///         assert_eq!(rest, i % 7);
///         lines.push(text.clone());
///         Ok::<(), std::io::Error>(())
///     },
/// )?;
/// assert_eq!(lines[999], "line 999");
/// # Ok::<(), std::io::Error>(())
/// ```
pub fn for_each_ordered<S, R, E>(
    range: Range<u64>,
    ring: usize,
    make: impl Fn(u64, &mut S) -> R + Sync,
    consume: impl FnMut(u64, &S, R) -> Result<(), E> + Send,
) -> Result<(), E>
where
    S: Default + Send,
    R: Send,
    E: Send,
{
    let ring = ring.max(1);
    let shared = Ring {
        slots: (0..ring)
            .map(|_| {
                Mutex::new(Slot {
                    buffers: S::default(),
                    result: None,
                })
            })
            .collect(),
        ready: (0..ring).map(|_| AtomicU64::new(0)).collect(),
        next: AtomicU64::new(range.start),
        consumed: AtomicU64::new(range.start),
        consuming: AtomicBool::new(false),
        consumer: Mutex::new((consume, None)),
        stopped: AtomicBool::new(false),
        waiting: AtomicUsize::new(0),
        waits: Mutex::new(()),
        freed: Condvar::new(),
        ring: ring as u64,
        end: range.end,
    };
    rayon::broadcast(|_| {
        let _guard = PanicGuard(&shared);
        loop {
            let i = shared.next.fetch_add(1, SeqCst);
            if i >= shared.end || !shared.wait_for_slot(i) {
                return;
            }
            let at = shared.at(i);
            let mut slot = lock(&shared.slots[at]);
            slot.result = Some(make(i, &mut slot.buffers));
            drop(slot);
            shared.ready[at].store(i + 1, SeqCst);
            shared.consume_made();
        }
    });
    let (_, error) = shared
        .consumer
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner);
    match error {
        Some(e) => Err(e),
        None => {
            debug_assert!(
                range.is_empty() || shared.consumed.load(SeqCst) == range.end,
                "every index made is consumed"
            );
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    /// Runs `test` on a thread of its own and fails if it is not done within `limit`: a
    /// lost hand-over hangs the pipeline rather than failing an assertion. A panic of
    /// `test` comes out as it is.
    fn within(limit: Duration, test: impl FnOnce() + Send + 'static) {
        let (done, finished) = std::sync::mpsc::channel();
        let run = std::thread::spawn(move || {
            test();
            let _ = done.send(());
        });
        match finished.recv_timeout(limit) {
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => panic!("the pipeline hung"),
            _ => run.join().unwrap(),
        }
    }

    /// Makes `range` on `threads` threads with a ring of `ring`, checking the order and
    /// every result, with `pause(i, side)` called before making (side 1) and consuming
    /// (side 2) index `i`.
    fn in_order(threads: usize, ring: usize, range: Range<u64>, pause: impl Fn(u64, u64) + Sync) {
        let pool = pool(threads);
        let mut next = range.start;
        pool.install(|| {
            for_each_ordered(
                range.clone(),
                ring,
                |i, buf: &mut String| {
                    pause(i, 1);
                    buf.clear();
                    buf.push_str(&i.to_string());
                    i * 2
                },
                |i, buf, r| {
                    pause(i, 2);
                    assert_eq!(
                        (i, buf.as_str(), r),
                        (next, next.to_string().as_str(), next * 2)
                    );
                    next += 1;
                    Ok::<(), String>(())
                },
            )
        })
        .unwrap();
        assert_eq!(next, range.end, "{threads} threads, ring {ring}");
    }

    #[test]
    fn every_index_is_consumed_once_in_order_for_any_thread_count() {
        within(Duration::from_secs(60), || {
            for threads in [1, 2, 4] {
                for ring in [1, 3, 128] {
                    in_order(threads, ring, 5..1_005, |_, _| {});
                }
            }
        });
    }

    /// Every interleaving the hand-over has to survive: more threads than cores, rings
    /// smaller than the pool, and makers and consumers that yield or sleep at random
    /// (from the index, so each run is the same program).
    #[test]
    fn random_delays_on_both_sides_keep_the_order_and_never_hang() {
        within(Duration::from_secs(60), || {
            let pause =
                |i: u64, side: u64| match (i ^ side).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 60 {
                    0 => std::thread::sleep(Duration::from_micros(200)),
                    1..=4 => std::thread::yield_now(),
                    _ => {}
                };
            for threads in [2, 3, 8] {
                for ring in [1, 2, 5] {
                    in_order(threads, ring, 0..3_000, pause);
                }
            }
        });
    }

    #[test]
    fn the_consumer_runs_on_one_thread_at_a_time_and_waits_free_the_ring() {
        within(Duration::from_secs(60), || {
            let pool = pool(4);
            let inside = AtomicBool::new(false);
            let mut seen = 0;
            pool.install(|| {
                for_each_ordered(
                    0..400,
                    2,
                    |i, _: &mut ()| i,
                    |i, _, r| {
                        assert!(!inside.swap(true, SeqCst), "two consumers at once");
                        assert_eq!(i, r);
                        // A slow consumer: the workers fill the ring of 2 and wait.
                        if i % 50 == 0 {
                            std::thread::sleep(Duration::from_millis(2));
                        }
                        seen += 1;
                        inside.store(false, SeqCst);
                        Ok::<(), String>(())
                    },
                )
            })
            .unwrap();
            assert_eq!(seen, 400);
        });
    }

    #[test]
    fn a_consumer_error_stops_the_workers_and_is_returned() {
        within(Duration::from_secs(60), || {
            let pool = pool(2);
            let made = AtomicU64::new(0);
            let r = pool.install(|| {
                for_each_ordered(
                    0..1_000_000,
                    8,
                    |_, _: &mut ()| {
                        made.fetch_add(1, SeqCst);
                    },
                    |i, _, ()| if i == 10 { Err("full".into()) } else { Ok(()) },
                )
            });
            assert_eq!(r, Err("full".to_string()));
            // At most the ring and the indices the two workers had taken.
            assert!(made.load(SeqCst) <= 11 + 8 + 2);
        });
    }

    #[test]
    fn a_worker_panic_reaches_the_caller_instead_of_hanging_the_writer() {
        within(Duration::from_secs(60), || {
            let pool = pool(2);
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool.install(|| {
                    for_each_ordered(
                        0..10_000,
                        8,
                        |i, _: &mut ()| assert!(i != 100, "made to fail"),
                        |_, _, ()| Ok::<(), String>(()),
                    )
                })
            }));
            assert!(outcome.is_err());
        });
    }

    #[test]
    fn an_empty_range_makes_nothing() {
        let r = for_each_ordered(3..3, 4, |_, _: &mut ()| (), |_, _, ()| Ok::<(), String>(()));
        assert_eq!(r, Ok(()));
    }
}
