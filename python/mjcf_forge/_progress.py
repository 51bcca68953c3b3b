"""Progress of the batch calls: the ``progress=`` option of :meth:`Scene.variants`,
:meth:`ModelCache.batch` and :class:`mjcf_forge.batch.WorldBatch`.

``progress`` is one of:

- ``None`` or ``False`` (the default): no progress, and no cost;
- ``True``: a ``tqdm`` bar when ``tqdm`` is installed, else one plain line on standard error
  at most every second (``mjcf-forge: variants 4000/10000 (40%), 2.0 s``) and one at the end;
- an object with ``update(n)`` (a ``tqdm`` bar of your own, or anything shaped like one): its
  ``update`` is called with the number of items done since the last call; it is yours, so it
  is not closed;
- a callable: called as ``progress(n)`` in the same way.

Counts are exact at the end; on the way they may lag by a handful of items (a variant
stream reports per batch it hands over, not per variant).
"""

from __future__ import annotations

import sys
import time
from typing import Any, Callable, Optional


class _Lines:
    """The fallback without tqdm: a line on standard error at most every ``every`` seconds,
    and one when done."""

    def __init__(self, total: Optional[int], what: str, every: float = 1.0) -> None:
        self.total, self.what, self.every = total, what, every
        self.done = 0
        self.start = self.last = time.monotonic()
        self.closed = False

    def update(self, n: int = 1) -> None:
        self.done += n
        now = time.monotonic()
        if now - self.last >= self.every:
            self.last = now
            self._line(now)

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            self._line(time.monotonic())

    def _line(self, now: float) -> None:
        if self.total:
            count = f"{self.done}/{self.total} ({100 * self.done // self.total}%)"
        else:
            count = str(self.done)
        print(f"mjcf-forge: {self.what} {count}, {now - self.start:.1f} s", file=sys.stderr, flush=True)


class _Owned:
    """A tqdm bar made here: closed when the call ends."""

    def __init__(self, bar: Any) -> None:
        self.bar = bar
        self.update = bar.update

    def close(self) -> None:
        self.bar.close()


class _Given:
    """The caller's own: ``update(n)`` called, never closed."""

    def __init__(self, update: Callable[[int], Any]) -> None:
        self.update = update

    def close(self) -> None:
        pass


def progress_of(progress: Any, total: Optional[int], what: str) -> Any:
    """What a batch call reports to: ``None`` for no progress, else an object with
    ``update(n)`` and ``close()`` (see the module). A ``TypeError`` for any other value."""
    if progress is None or progress is False:
        return None
    if progress is True:
        try:
            from tqdm import tqdm
        except ImportError:
            return _Lines(total, what)
        return _Owned(tqdm(total=total, desc=what, unit=what[:-1] if what.endswith("s") else what))
    update = getattr(progress, "update", None)
    if callable(update):
        return _Given(update)
    if callable(progress):
        return _Given(progress)
    raise TypeError(
        "progress is True, False, None, an object with update(n) (a tqdm bar) or a "
        f"callable, not {type(progress).__name__}"
    )
