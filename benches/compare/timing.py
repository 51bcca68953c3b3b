"""The timing helpers every same-run comparison here shares (imported by the scripts
beside it: ``from timing import ...``; each script runs with its own venv, so this module
needs the standard library only).

Figures are medians (and bests) of repeated runs in one process, or of processes
alternated by the calling script: ratios, since the machines are shared and noisy.

>>> ms = each_ms(lambda i: None, 3)
>>> len(ms), sorted(summary(ms))
(3, ['best_ms', 'median_ms', 'runs'])
"""

from __future__ import annotations

import statistics
import time
import timeit
from typing import Callable


def each_ms(fn: Callable[[int], object], runs: int, warmup: int = 1) -> list[float]:
    """Milliseconds of each of ``runs`` calls ``fn(1)`` .. ``fn(runs)``, after ``warmup``
    calls ``fn(0)``."""
    for _ in range(warmup):
        fn(0)
    out = []
    for i in range(1, runs + 1):
        t = time.perf_counter()
        fn(i)
        out.append((time.perf_counter() - t) * 1e3)
    return out


def summary(ms: list[float], digits: int | None = None) -> dict:
    """Best and median of ``ms`` (rounded to ``digits`` when given) and how many runs."""
    best, median = min(ms), statistics.median(ms)
    if digits is not None:
        best, median = round(best, digits), round(median, digits)
    return {"best_ms": best, "median_ms": median, "runs": len(ms)}


def mean_seconds(fn: Callable[[], object], n: int) -> float:
    """Seconds per call over ``n`` calls of ``fn()`` in a row."""
    t = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - t) / n


def per_call(fn: Callable[[], object], budget: float = 0.3) -> float:
    """Seconds per call: the best of five runs of about ``budget`` seconds each."""
    n, took = 1, 0.0
    while took < budget / 10:
        n *= 2
        took = timeit.timeit(fn, number=n)
    n = max(1, int(n * budget / 5 / took))
    return min(timeit.repeat(fn, number=n, repeat=5)) / n


def wall_and_cpu(fn: Callable[[], object], runs: int, warmup: int) -> dict:
    """Best and median wall and CPU milliseconds of ``runs`` calls of ``fn()`` after
    ``warmup``."""
    for _ in range(warmup):
        fn()
    wall, cpu = [], []
    for _ in range(runs):
        c0, t0 = time.process_time(), time.perf_counter()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return {
        "best": round(min(wall) * 1e3, 3),
        "median": round(statistics.median(wall) * 1e3, 3),
        "cpu_best": round(min(cpu) * 1e3, 3),
        "cpu_median": round(statistics.median(cpu) * 1e3, 3),
    }
