//! The shared document behind `Document` and `Element`, and the registry of element proxies.
//!
//! A [`DocCell`] holds one `mjcf_forge::Document` (its own, or the one inside a `Model`)
//! behind a lock, and a registry of the live `Element` proxies of its nodes: one proxy per
//! node, as lxml keeps one `_Element` per libxml2 node, so that `a is b` holds for the same
//! element and a handle kept by user code stays the handle. The registry holds weak
//! references; a proxy leaves it when Python frees it.
//!
//! A proxy's target (cell and node) can change: when its element is copied into another
//! document (a merge, `append` across documents), [`retarget`] points the live proxies of
//! the copied nodes at their copies, which is what code written for ElementTree expects
//! when it moves elements between trees.
//!
//! Locks: taken with the GIL held through `*_py_attached`, which let go of the GIL while
//! they wait, so a thread waiting for a lock never blocks the thread holding it. Code that
//! runs with the GIL released (`errors::run`) takes them directly.

use std::ops::{Deref, DerefMut};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, RwLock, RwLockReadGuard, RwLockWriteGuard};

use ahash::AHashMap;
use mjcf_forge::{Document, Node, NodeMap, XmlModel};
use pyo3::prelude::*;
use pyo3::sync::{MutexExt, RwLockExt};
use pyo3::types::PyWeakrefReference;

use super::element::PyElement;

/// A document shared by a `Document`, its `Element`s and perhaps a `Model`.
pub(crate) struct DocCell {
    host: Host,
    registry: Mutex<Registry>,
}

/// Where the document lives.
// One per document, behind an `Arc`: its size does not matter, an indirection on every
// access would.
#[allow(clippy::large_enum_variant)]
enum Host {
    Own(RwLock<Document>),
    /// A model's document, locked with the model (its lists and offsets sit beside it).
    Model(Arc<RwLock<XmlModel>>),
}

/// The live proxies of a cell's nodes.
#[derive(Default)]
struct Registry {
    proxies: AHashMap<Node, Entry>,
    /// Dead entries (their proxy freed while the registry was busy) are swept when the
    /// map passes this size.
    sweep_at: usize,
    /// Subtrees appended into other documents ([`alias`]), the latest last: where each
    /// copied node went. Nodes are never freed (removing detaches), so a node id keeps
    /// meaning the node it was recorded for.
    aliases: Vec<(Arc<DocCell>, NodeMap)>,
}

struct Entry {
    proxy: Py<PyWeakrefReference>,
    /// The proxy's serial: a freed proxy removes its entry only if it is still its own.
    serial: u64,
}

/// Serials of proxies, unique in the process.
static SERIALS: AtomicU64 = AtomicU64::new(1);

pub(crate) fn next_serial() -> u64 {
    SERIALS.fetch_add(1, Ordering::Relaxed)
}

/// A read lock on a cell's document.
pub(crate) enum DocRead<'a> {
    Own(RwLockReadGuard<'a, Document>),
    Model(RwLockReadGuard<'a, XmlModel>),
}

/// A write lock on a cell's document.
pub(crate) enum DocWrite<'a> {
    Own(RwLockWriteGuard<'a, Document>),
    Model(RwLockWriteGuard<'a, XmlModel>),
}

impl Deref for DocRead<'_> {
    type Target = Document;
    fn deref(&self) -> &Document {
        match self {
            DocRead::Own(g) => g,
            DocRead::Model(g) => g.document(),
        }
    }
}

impl Deref for DocWrite<'_> {
    type Target = Document;
    fn deref(&self) -> &Document {
        match self {
            DocWrite::Own(g) => g,
            DocWrite::Model(g) => g.document(),
        }
    }
}

impl DerefMut for DocWrite<'_> {
    fn deref_mut(&mut self) -> &mut Document {
        match self {
            DocWrite::Own(g) => g,
            DocWrite::Model(g) => g.document_mut(),
        }
    }
}

/// Locks survive poisoning: the panic behind it was already reported as an `MjcfError`.
fn unpoison<G>(r: Result<G, std::sync::PoisonError<G>>) -> G {
    r.unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl DocCell {
    /// A cell owning `doc`.
    pub(crate) fn new(doc: Document) -> Arc<DocCell> {
        Arc::new(DocCell {
            host: Host::Own(RwLock::new(doc)),
            registry: Mutex::new(Registry::default()),
        })
    }

    /// A cell over the document of `model`.
    pub(crate) fn of_model(model: Arc<RwLock<XmlModel>>) -> Arc<DocCell> {
        Arc::new(DocCell {
            host: Host::Model(model),
            registry: Mutex::new(Registry::default()),
        })
    }

    /// Reads the document (GIL held: waits without it).
    pub(crate) fn read(&self, py: Python<'_>) -> DocRead<'_> {
        match &self.host {
            Host::Own(l) => DocRead::Own(unpoison(l.read_py_attached(py))),
            Host::Model(l) => DocRead::Model(unpoison(l.read_py_attached(py))),
        }
    }

    /// Changes the document (GIL held: waits without it).
    pub(crate) fn write(&self, py: Python<'_>) -> DocWrite<'_> {
        match &self.host {
            Host::Own(l) => DocWrite::Own(unpoison(l.write_py_attached(py))),
            Host::Model(l) => DocWrite::Model(unpoison(l.write_py_attached(py))),
        }
    }

    /// Reads the document from code running with the GIL released.
    pub(crate) fn read_detached(&self) -> DocRead<'_> {
        match &self.host {
            Host::Own(l) => DocRead::Own(unpoison(l.read())),
            Host::Model(l) => DocRead::Model(unpoison(l.read())),
        }
    }

    /// Changes the document from code running with the GIL released.
    pub(crate) fn write_detached(&self) -> DocWrite<'_> {
        match &self.host {
            Host::Own(l) => DocWrite::Own(unpoison(l.write())),
            Host::Model(l) => DocWrite::Model(unpoison(l.write())),
        }
    }

    /// Reads `src` and changes `dst` (two cells) at once. The locks are taken in one order
    /// for every pair (by address), so two threads copying between the same two documents
    /// in opposite directions cannot each hold one lock and wait for the other.
    pub(crate) fn read_and_write<'a>(
        py: Python<'_>,
        src: &'a DocCell,
        dst: &'a DocCell,
    ) -> (DocRead<'a>, DocWrite<'a>) {
        if std::ptr::from_ref(src) < std::ptr::from_ref(dst) {
            let r = src.read(py);
            (r, dst.write(py))
        } else {
            let w = dst.write(py);
            (src.read(py), w)
        }
    }

    fn registry(&self, py: Python<'_>) -> MutexGuard<'_, Registry> {
        unpoison(self.registry.lock_py_attached(py))
    }

    /// The live proxy of `node`, if there is one.
    fn live<'py>(&self, py: Python<'py>, node: Node) -> Option<Bound<'py, PyElement>> {
        let weak = self
            .registry(py)
            .proxies
            .get(&node)
            .map(|e| e.proxy.clone_ref(py))?;
        // Upgraded outside the lock: dropping a strong reference may free a proxy, whose
        // own clean-up takes the lock.
        weak.bind(py)
            .upgrade()
            .and_then(|o| o.cast_into::<PyElement>().ok())
    }

    /// Records `proxy` as the proxy of `node`, unless another one got there first (making
    /// a Python object may run other threads' code): then that one is the proxy.
    fn register<'py>(
        &self,
        py: Python<'py>,
        node: Node,
        proxy: Bound<'py, PyElement>,
    ) -> PyResult<Bound<'py, PyElement>> {
        let weak = PyWeakrefReference::new(&proxy)?.unbind();
        let serial = proxy.get().serial();
        let mut reg = self.registry(py);
        if let Some(first) = reg
            .proxies
            .get(&node)
            .and_then(|e| e.proxy.bind(py).upgrade())
        {
            drop(reg);
            return Ok(first.cast_into::<PyElement>()?);
        }
        let old = reg.proxies.insert(
            node,
            Entry {
                proxy: weak,
                serial,
            },
        );
        if reg.proxies.len() > reg.sweep_at {
            reg.proxies
                .retain(|_, e| e.proxy.bind(py).upgrade().is_some());
            reg.sweep_at = (2 * reg.proxies.len()).max(1024);
        }
        drop(reg);
        drop(old);
        Ok(proxy)
    }

    /// Forgets the entry of `node` if it is the proxy `serial`'s. Called while a proxy is
    /// freed, which may happen inside a registry call of this very thread: then the entry
    /// stays, dead, until it is replaced or swept.
    pub(crate) fn forget(&self, node: Node, serial: u64) {
        let removed = match self.registry.try_lock() {
            Ok(mut reg) => match reg.proxies.get(&node) {
                Some(e) if e.serial == serial => reg.proxies.remove(&node),
                _ => None,
            },
            Err(_) => None,
        };
        drop(removed);
    }
}

/// Where `node` of `cell` answers from: the copy it was last appended as into another
/// document (followed on, if that copy was appended on too), or itself.
fn resolve(py: Python<'_>, cell: &Arc<DocCell>, node: Node) -> Option<(Arc<DocCell>, Node)> {
    let mut at: Option<(Arc<DocCell>, Node)> = None;
    loop {
        let (c, n) = at.as_ref().map_or((cell, node), |(c, n)| (c, *n));
        let next = c
            .registry(py)
            .aliases
            .iter()
            .rev()
            .find_map(|(to, map)| Some((to.clone(), map.get(n)?)));
        match next {
            Some(next) => at = Some(next),
            None => return at,
        }
    }
}

/// Makes the nodes of `from` that `map` copied into `to` answer with their copies from now
/// on (see the module's documentation).
pub(crate) fn alias(py: Python<'_>, from: &Arc<DocCell>, to: &Arc<DocCell>, map: &NodeMap) {
    if Arc::ptr_eq(from, to) || map.is_empty() {
        return;
    }
    from.registry(py).aliases.push((to.clone(), map.clone()));
}

/// The one proxy of `node` in `cell`: the live one, or a new one, registered; for a node
/// appended into another document, its copy's.
pub(crate) fn proxy<'py>(
    py: Python<'py>,
    cell: &Arc<DocCell>,
    node: Node,
) -> PyResult<Bound<'py, PyElement>> {
    if let Some((to, copy)) = resolve(py, cell, node) {
        return proxy(py, &to, copy);
    }
    if let Some(p) = cell.live(py, node) {
        return Ok(p);
    }
    let p = Bound::new(py, PyElement::at(cell.clone(), node))?;
    cell.register(py, node, p)
}

/// Proxies of several nodes, in order: the live ones found under one lock, the others made
/// (what `findall` and iteration return, so the common path).
pub(crate) fn proxies<'py>(
    py: Python<'py>,
    cell: &Arc<DocCell>,
    nodes: impl IntoIterator<Item = Node>,
) -> PyResult<Vec<Bound<'py, PyElement>>> {
    let nodes: Vec<Node> = nodes.into_iter().collect();
    if !cell.registry(py).aliases.is_empty() {
        return nodes.into_iter().map(|n| proxy(py, cell, n)).collect();
    }
    let found: Vec<Option<Bound<'py, PyAny>>> = {
        let reg = cell.registry(py);
        // Upgrading makes a strong reference, which frees nothing: safe under the lock.
        nodes
            .iter()
            .map(|n| reg.proxies.get(n).and_then(|e| e.proxy.bind(py).upgrade()))
            .collect()
    };
    nodes
        .into_iter()
        .zip(found)
        .map(
            |(n, f)| match f.and_then(|o| o.cast_into::<PyElement>().ok()) {
                Some(p) => Ok(p),
                None => {
                    let p = Bound::new(py, PyElement::at(cell.clone(), n))?;
                    cell.register(py, n, p)
                }
            },
        )
        .collect()
}

/// Points the live proxies of `from`'s nodes that `map` copied into `to` at their copies.
/// A copy that already has a proxy of its own (an asset a merge shared) keeps it, and the
/// old proxy stays where it was.
pub(crate) fn retarget(py: Python<'_>, from: &Arc<DocCell>, to: &Arc<DocCell>, map: &NodeMap) {
    if Arc::ptr_eq(from, to) || map.is_empty() {
        return;
    }
    let moving: Vec<(Node, Node, Py<PyWeakrefReference>)> = from
        .registry(py)
        .proxies
        .iter()
        .filter_map(|(&old, e)| Some((old, map.get(old)?, e.proxy.clone_ref(py))))
        .collect();
    for (old, new, weak) in moving {
        let Some(p) = weak
            .bind(py)
            .upgrade()
            .and_then(|o| o.cast_into::<PyElement>().ok())
        else {
            continue;
        };
        if to.live(py, new).is_some() {
            continue;
        }
        let serial = p.get().serial();
        let entry = {
            let mut reg = from.registry(py);
            match reg.proxies.get(&old) {
                Some(e) if e.serial == serial => reg.proxies.remove(&old),
                _ => None,
            }
        };
        let Some(entry) = entry else { continue };
        p.get().point_at(to.clone(), new);
        let replaced = to.registry(py).proxies.insert(new, entry);
        drop(replaced);
    }
}
