#!/usr/bin/env python3
"""How fast lift5 variants reach Python: ``scene.variants(range, threads=T)`` (made on Rust
threads, handed over in order) against ``scene.variant(i)`` one at a time on the Python
thread, and the Rust work alone (``_testing.rust_seconds``: the same variants made in a Rust
loop, no Python object). Every variant's ``.xml`` is read, as a caller writing or
compiling it would.

Run: .cache/venv/bin/python benches/compare/bench_python_stream.py [--n N] [--rounds R]
(after scripts/setup.sh, which installs the package into .cache/venv and unpacks the
robosuite models benches/scenes/lift5.toml uses). Rounds alternate the ways; the best
and median of each are printed, in variants per second.
"""

import argparse
import statistics
import time
from pathlib import Path

import mjcf_forge
from mjcf_forge._mjcf_forge import _testing

ROOT = Path(__file__).resolve().parents[2]


def rate(n, run):
    start = time.perf_counter()
    run()
    return n / (time.perf_counter() - start)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=60_000, help="variants per run")
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    scene = mjcf_forge.Scene.load(ROOT / "benches/scenes/lift5.toml")
    n = args.n
    # Every slot's object instances are made on first use: make them before timing.
    _testing.rust_seconds(scene, list(range(2_000)))

    def stream(threads, base):
        def run():
            for v in scene.variants(range(base, base + n), threads=threads):
                len(v.xml)

        return run

    def one_at_a_time(base):
        def run():
            for i in range(base, base + n):
                len(scene.variant(i).xml)

        return run

    def rust_only(base):
        def run():
            _testing.rust_seconds(scene, list(range(base, base + n)))

        return run

    ways = {
        "variants(threads=1)": lambda b: stream(1, b),
        "variants(threads=2)": lambda b: stream(2, b),
        "variant(i) one at a time": one_at_a_time,
        "Rust alone, one thread": rust_only,
    }
    rates = {name: [] for name in ways}
    for r in range(args.rounds):
        for k, (name, way) in enumerate(ways.items()):
            # New indices for every run: every variant is a new draw.
            rates[name].append(rate(n, way((r * len(ways) + k) * n)))
    print(f"lift5, {n} variants per run, {args.rounds} rounds (variants per second)")
    for name, rs in rates.items():
        print(f"  {name:26} best {max(rs):9.0f}  median {statistics.median(rs):9.0f}")


if __name__ == "__main__":
    main()
