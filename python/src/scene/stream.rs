//! The variant stream (`Scene.variants`): a producer thread makes variants on a rayon
//! pool into a ring of `window` slots (`mjcf_forge::output::for_each_ordered`: no worker
//! waits for another) and hands them over in order, in batches of half a window through a
//! channel of one batch, so memory stays bounded however many indices are asked for.
//! Batches, because a hand-over per variant cost a wake-up of the Python thread and a
//! release of the GIL each: two futex calls and about one context switch per variant.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::sync::{Arc, Mutex};

use mjcf_forge::scene::Scene;
use pyo3::prelude::*;

use super::variant::{Made, Origin, PyVariant, make};
use crate::errors::Failure;

/// What a batch of the variant stream holds: made variants in order, a failure last.
type Batch = Vec<Result<Made, Failure>>;

/// The producer: variants made in parallel into a ring of `window`, sent in order in
/// batches of `batch` (the last one shorter); stops when the receiver is gone (the Python
/// iterator was dropped) or after the first failure, which ends its batch.
fn produce(
    scene: Arc<Scene>,
    indices: Vec<u64>,
    pool: Option<rayon::ThreadPool>,
    window: usize,
    batch: usize,
    tx: SyncSender<Batch>,
) {
    let run = move || {
        let last = indices.len() as u64;
        let mut pending: Batch = Vec::with_capacity(batch);
        // Err(()) only stops the workers: the receiver is gone or has its failure.
        let _ = mjcf_forge::output::for_each_ordered(
            0..last,
            window,
            |k, _: &mut ()| make(&scene, indices[k as usize]),
            move |k, (), made| {
                let failed = made.is_err();
                pending.push(made);
                if failed || pending.len() >= batch || k + 1 == last {
                    let full = std::mem::replace(&mut pending, Vec::with_capacity(batch));
                    if tx.send(full).is_err() || failed {
                        return Err(());
                    }
                }
                Ok(())
            },
        );
    };
    match &pool {
        Some(pool) => pool.install(run),
        None => run(),
    }
}

/// An iterator over variants made on Rust threads (see :meth:`Scene.variants`).
#[pyclass(name = "VariantIterator", module = "mjcf_forge", frozen)]
pub(crate) struct PyVariantIter {
    taken: Mutex<Taken>,
    /// For the variants' documents, made on demand.
    scene: Arc<Scene>,
    /// Where progress goes (`mjcf_forge._progress`), if anywhere: told of the variants
    /// handed over once per batch, so that it costs one Python call per batch.
    progress: Option<Py<PyAny>>,
    /// Variants handed over since progress was last told.
    unreported: AtomicUsize,
    /// Progress was closed (the stream ended).
    closed: AtomicBool,
}

/// The stream's receiving end and the batch being handed out.
struct Taken {
    /// `None` once exhausted or failed.
    rx: Option<Receiver<Batch>>,
    batch: VecDeque<Result<Made, Failure>>,
}

impl Taken {
    /// The next variant of the batch at hand, or of the next batch (waiting for it if
    /// `wait`). `None`: the stream is over, or (without `wait`) nothing is at hand.
    fn next(&mut self, wait: bool) -> Option<Result<Made, Failure>> {
        if self.batch.is_empty() && wait {
            match self.rx.as_ref().and_then(|r| r.recv().ok()) {
                Some(batch) => self.batch.extend(batch),
                None => self.rx = None,
            }
        }
        let got = self.batch.pop_front();
        if matches!(got, Some(Err(_))) {
            // A failure ends the stream: later calls stop at once.
            self.rx = None;
            self.batch.clear();
        }
        got
    }
}

impl PyVariantIter {
    /// Starts the producer for `indices` on `threads` workers (all cores without it) with
    /// a ring of `window` (see :meth:`Scene.variants`), and returns the receiving end.
    pub(super) fn start(
        scene: Arc<Scene>,
        indices: Vec<u64>,
        threads: Option<usize>,
        window: Option<usize>,
        progress: Option<Py<PyAny>>,
    ) -> Result<PyVariantIter, Failure> {
        let pool = match threads {
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .thread_name(|i| format!("mjcf-forge-variants-{i}"))
                    .build()
                    .map_err(|e| Failure::new(vec![format!("cannot start {n} threads: {e}")]))?,
            ),
            None => None,
        };
        let workers = threads.unwrap_or_else(rayon::current_num_threads);
        let window = window.unwrap_or((8 * workers).max(16));
        let batch = (window / 2).max(1);
        let (tx, rx) = sync_channel(1);
        std::thread::Builder::new()
            .name("mjcf-forge-variants".into())
            .spawn({
                let scene = scene.clone();
                move || produce(scene, indices, pool, window, batch, tx)
            })
            .map_err(|e| Failure::new(vec![format!("cannot start the producer thread: {e}")]))?;
        Ok(PyVariantIter {
            taken: Mutex::new(Taken {
                rx: Some(rx),
                batch: VecDeque::new(),
            }),
            scene,
            progress,
            unreported: AtomicUsize::new(0),
            closed: AtomicBool::new(false),
        })
    }

    /// Tells progress of the variants handed over since last told; and closes it when the
    /// stream is over (once).
    fn report(&self, py: Python<'_>, over: bool) -> PyResult<()> {
        let Some(progress) = &self.progress else {
            return Ok(());
        };
        let done = self.unreported.swap(0, Ordering::Relaxed);
        if done > 0 {
            progress.bind(py).call_method1("update", (done,))?;
        }
        if over && !self.closed.swap(true, Ordering::Relaxed) {
            progress.bind(py).call_method0("close")?;
        }
        Ok(())
    }
}

#[pymethods]
impl PyVariantIter {
    fn __iter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<PyVariant>> {
        // A variant of the batch at hand is taken with the GIL held; waiting for the next
        // batch releases it (the workers never need it). The lock is never waited for
        // with the GIL held: a thread that holds it may be waiting for a batch.
        let at_hand = match self.taken.try_lock() {
            Ok(mut taken) => taken.next(false),
            Err(_) => None,
        };
        let next = match at_hand {
            Some(made) => Some(made),
            None => {
                // Before waiting for the next batch: what was handed over of the last.
                self.report(py, false)?;
                py.detach(|| {
                    let mut taken = self.taken.lock().unwrap_or_else(|p| p.into_inner());
                    taken.next(true)
                })
            }
        };
        match next {
            Some(Ok(made)) => {
                if self.progress.is_some() {
                    self.unreported.fetch_add(1, Ordering::Relaxed);
                }
                Ok(Some(PyVariant::new(
                    made,
                    Origin::Scene(self.scene.clone()),
                )))
            }
            Some(Err(failure)) => {
                self.report(py, true)?;
                Err(failure.into())
            }
            None => {
                self.report(py, true)?;
                Ok(None)
            }
        }
    }
}
