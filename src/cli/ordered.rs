//! Made in parallel, consumed in order, with no barrier between batches: every thread of
//! the current rayon pool takes the next index as soon as it is done with one, into a ring
//! of reused slots, while a consuming thread of its own takes the made ones in index
//! order. Workers wait only when the ring is full (the consumer is behind by `ring`
//! indices), the consumer only when the next index is not made yet.
//!
//! A pipeline made of chunks (each made in parallel, then handed over) stops every worker
//! at the end of each chunk until the slowest is done; on two cores that idled about 5%
//! of the time.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};

/// Where the workers and the consumer meet. Indices are taken from `next`; index `i` is
/// made into `slots[i % ring]` once the consumer is done with index `i - ring`.
struct Ring<S, R> {
    slots: Vec<Mutex<Slot<S, R>>>,
    next: AtomicU64,
    state: Mutex<State>,
    /// Workers waiting for the consumer to free a slot.
    freed: Condvar,
    /// The consumer waiting for made indices.
    made: Condvar,
}

struct Slot<S, R> {
    buffers: S,
    result: Option<R>,
}

struct State {
    /// The next index the consumer takes; every index before it is consumed.
    consumed: u64,
    /// Per slot: made and not yet consumed.
    ready: Vec<bool>,
    /// While the consumer waits: the last index of the run it waits for.
    consumer_waits_to: Option<u64>,
    workers_waiting: usize,
    /// The consumer stopped on an error, or a worker panicked: workers take no more
    /// indices.
    stopped: bool,
    /// A worker panicked: the index it was making never comes.
    worker_panicked: bool,
}

/// Tells the consumer when a worker unwinds, so that it stops waiting for the index that
/// worker was making (the panic itself goes on to the caller).
struct PanicGuard<'a> {
    state: &'a Mutex<State>,
    made: &'a Condvar,
    freed: &'a Condvar,
}

impl Drop for PanicGuard<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            let mut st = lock(self.state);
            st.stopped = true;
            st.worker_panicked = true;
            self.made.notify_all();
            self.freed.notify_all();
        }
    }
}

/// Lock, ignoring poisoning: a panic on one side is reported by the scope that joins it,
/// and the state is whole between statements.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Makes every index of `range` with `make` on all threads of the current rayon pool and
/// hands each result, in index order, to `consume` on a thread of its own. `make` fills
/// the reused buffers of its slot (`ring` slots, each `S::default()` at first) and gives
/// its result; `consume` sees the slot's buffers and the result. The consumer is woken
/// for runs of `batch` made indices (fewer at the end), not for each one. An error from
/// `consume` stops the workers and is returned; indices already taken are still made.
///
/// Called from inside a rayon pool (`ThreadPool::install`), it uses that pool's threads.
pub fn for_each_ordered<S, R>(
    range: Range<u64>,
    ring: usize,
    batch: u64,
    make: impl Fn(u64, &mut S) -> R + Sync,
    mut consume: impl FnMut(u64, &S, R) -> Result<(), String> + Send,
) -> Result<(), String>
where
    S: Default + Send,
    R: Send,
{
    let ring = ring.max(1);
    let batch = batch.clamp(1, ring as u64);
    let shared = Ring {
        slots: (0..ring)
            .map(|_| {
                Mutex::new(Slot {
                    buffers: S::default(),
                    result: None,
                })
            })
            .collect(),
        next: AtomicU64::new(range.start),
        state: Mutex::new(State {
            consumed: range.start,
            ready: vec![false; ring],
            consumer_waits_to: None,
            workers_waiting: 0,
            stopped: false,
            worker_panicked: false,
        }),
        freed: Condvar::new(),
        made: Condvar::new(),
    };
    let at = |i: u64| (i % ring as u64) as usize;
    let ring_len = ring as u64;
    let end = range.end;
    std::thread::scope(|scope| {
        let shared = &shared;
        let consumer = scope.spawn(move || -> Result<(), String> {
            let mut i = range.start;
            while i < end {
                // The run of made indices from `i` on, waiting for one if none is made: the
                // consumer sleeps until `batch` of them are (one wake-up per run).
                let run = {
                    let mut st = lock(&shared.state);
                    if !st.ready[at(i)] {
                        let last = (i + batch - 1).min(end - 1);
                        st.consumer_waits_to = Some(last);
                        while !st.ready[at(i)] && !st.worker_panicked {
                            st = shared.made.wait(st).unwrap_or_else(PoisonError::into_inner);
                        }
                        st.consumer_waits_to = None;
                        if st.worker_panicked {
                            return Err("internal error: a worker thread panicked".to_string());
                        }
                    }
                    (i..end.min(i + ring_len))
                        .take_while(|&k| st.ready[at(k)])
                        .count() as u64
                };
                // Their slots are the consumer's until it frees them: no lock is contended.
                let mut outcome = Ok(());
                let mut done = 0;
                while done < run && outcome.is_ok() {
                    let k = i + done;
                    let mut slot = lock(&shared.slots[at(k)]);
                    outcome = match slot.result.take() {
                        Some(result) => consume(k, &slot.buffers, result),
                        None => Err("internal error: a made slot is empty".to_string()),
                    };
                    done += 1;
                }
                let mut st = lock(&shared.state);
                for k in i..i + done {
                    st.ready[at(k)] = false;
                }
                st.consumed = i + done;
                if outcome.is_err() {
                    st.stopped = true;
                }
                if st.workers_waiting > 0 || st.stopped {
                    shared.freed.notify_all();
                }
                drop(st);
                outcome?;
                i += done;
            }
            Ok(())
        });
        rayon::broadcast(|_| {
            let _guard = PanicGuard {
                state: &shared.state,
                made: &shared.made,
                freed: &shared.freed,
            };
            // One lock of the state per index: the last one marked made, the next one taken
            // (waiting while its slot is still the consumer's).
            let mut made: Option<u64> = None;
            loop {
                let i = {
                    let mut st = lock(&shared.state);
                    if let Some(m) = made {
                        st.ready[at(m)] = true;
                        // Wake the consumer once every index of the run it waits for is made.
                        if let Some(last) = st.consumer_waits_to {
                            let from = st.consumed;
                            if (from..=last).all(|k| st.ready[at(k)]) {
                                shared.made.notify_one();
                            }
                        }
                    }
                    let i = shared.next.fetch_add(1, Ordering::Relaxed);
                    if i >= end {
                        return;
                    }
                    while !st.stopped && i >= st.consumed + ring_len {
                        st.workers_waiting += 1;
                        st = shared
                            .freed
                            .wait(st)
                            .unwrap_or_else(PoisonError::into_inner);
                        st.workers_waiting -= 1;
                    }
                    if st.stopped {
                        return;
                    }
                    i
                };
                let mut slot = lock(&shared.slots[at(i)]);
                slot.result = Some(make(i, &mut slot.buffers));
                drop(slot);
                made = Some(i);
            }
        });
        consumer
            .join()
            .unwrap_or_else(|_| Err("internal error: the writing thread panicked".to_string()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_index_is_consumed_once_in_order_for_any_thread_count() {
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for (ring, batch) in [(1, 1), (3, 2), (128, 16)] {
                let mut seen = Vec::new();
                pool.install(|| {
                    for_each_ordered(
                        5..1_005,
                        ring,
                        batch,
                        |i, buf: &mut String| {
                            buf.clear();
                            buf.push_str(&i.to_string());
                            i * 2
                        },
                        |i, buf, r| {
                            assert_eq!(buf, &i.to_string());
                            assert_eq!(r, i * 2);
                            seen.push(i);
                            Ok(())
                        },
                    )
                })
                .unwrap();
                assert_eq!(seen, (5..1_005).collect::<Vec<_>>(), "{threads} {ring}");
            }
        }
    }

    #[test]
    fn a_consumer_error_stops_the_workers_and_is_returned() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let made = AtomicU64::new(0);
        let r = pool.install(|| {
            for_each_ordered(
                0..1_000_000,
                8,
                4,
                |_, _: &mut ()| {
                    made.fetch_add(1, Ordering::Relaxed);
                },
                |i, _, ()| if i == 10 { Err("full".into()) } else { Ok(()) },
            )
        });
        assert_eq!(r, Err("full".to_string()));
        // At most the ring and the indices the two workers had taken.
        assert!(made.load(Ordering::Relaxed) <= 11 + 8 + 2);
    }

    #[test]
    fn a_worker_panic_reaches_the_caller_instead_of_hanging_the_writer() {
        let (done, finished) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .unwrap();
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool.install(|| {
                    for_each_ordered(
                        0..10_000,
                        8,
                        4,
                        |i, _: &mut ()| assert!(i != 100, "made to fail"),
                        |_, _, ()| Ok(()),
                    )
                })
            }));
            let _ = done.send(outcome.is_err());
        });
        let panicked = finished
            .recv_timeout(std::time::Duration::from_secs(20))
            .expect("the pipeline hung after a worker panicked");
        assert!(panicked);
    }

    #[test]
    fn an_empty_range_makes_nothing() {
        let r = for_each_ordered(3..3, 4, 2, |_, _: &mut ()| (), |_, _, ()| Ok(()));
        assert_eq!(r, Ok(()));
    }
}
