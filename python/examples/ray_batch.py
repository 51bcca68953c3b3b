"""A large batch of scene variants as Ray tasks, one shard each, checked byte for byte
against one process making them all.

The driver puts the ``Scene`` into Ray's object store once; a ``Scene`` pickles as its
description (file, TOML text or dict), so each worker loads it again from the model files
(shared storage on a cluster) rather than receiving them. Each task makes its shard's
contiguous index range with ``scene.variants``. Variant ``i``
depends on ``(seed, i)`` only, so the shards put together are exactly what one process
makes, whatever the number of shards, their order or the machines they ran on. Each task
returns its shard as a tar archive in memory laid out as WebDataset shards are
(``NNNNNNNNN.xml`` + ``NNNNNNNNN.json`` per variant), which is also what it would write to
shared storage on a cluster.

Run: .cache/venv/bin/python python/examples/ray_batch.py [SCENE.toml] [-n N] [--shards K]
(a local Ray instance with 2 CPUs; set RAY_ADDRESS to use a running cluster instead)
"""
from __future__ import annotations

import argparse
import hashlib
import io
import os
import tarfile
import time
from pathlib import Path
import ray

import mjcf_forge


def shard_bounds(n: int, shards: int) -> list[tuple[int, int]]:
    """Contiguous [start, stop) ranges, sizes differing by at most one."""
    step, extra = divmod(n, shards)
    bounds, start = [], 0
    for k in range(shards):
        stop = start + step + (k < extra)
        bounds.append((start, stop))
        start = stop
    return bounds


def make_shard(scene: mjcf_forge.Scene, start: int, stop: int, threads: int = 1) -> bytes:
    """Variants [start, stop) as an uncompressed tar: per variant NNNNNNNNN.xml and .json."""
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w", format=tarfile.USTAR_FORMAT) as tar:
        for variant in scene.variants(range(start, stop), threads=threads):
            for suffix, text in (("xml", variant.xml), ("json", variant.params_json)):
                data = text.encode()
                info = tarfile.TarInfo(f"{variant.index:09d}.{suffix}")
                info.size = len(data)
                info.mtime = 0  # no clock in the bytes: the same shard, the same archive
                tar.addfile(info, io.BytesIO(data))
    return buffer.getvalue()


@ray.remote(num_cpus=1)
def make_shard_task(scene: mjcf_forge.Scene, start: int, stop: int) -> bytes:
    return make_shard(scene, start, stop)


def members(archives: list[bytes]) -> list[tuple[str, bytes]]:
    """Every member (name, content) of the archives, in order."""
    out = []
    for archive in archives:
        with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
            out += [(m.name, tar.extractfile(m).read()) for m in tar.getmembers()]
    return out


def run_batch(scene: mjcf_forge.Scene, n: int, shards: int) -> dict:
    """Makes the batch on Ray and in this process; returns the comparison."""
    t = time.perf_counter()
    scene_ref = ray.put(scene)
    refs = [make_shard_task.remote(scene_ref, a, b) for a, b in shard_bounds(n, shards)]
    sharded = ray.get(refs)
    ray_s = time.perf_counter() - t
    t = time.perf_counter()
    single = make_shard(scene, 0, n, threads=os.cpu_count() or 1)
    local_s = time.perf_counter() - t
    got, want = members(sharded), members([single])
    return {
        "variants": n,
        "shards": shards,
        "identical": got == want,
        "members": len(got),
        "sha256": hashlib.sha256(b"".join(content for _, content in got)).hexdigest(),
        "ray_s": ray_s,
        "one_process_s": local_s,
    }


def start_local_ray(num_cpus: int = 2) -> None:
    """A local Ray instance whose workers can import this file's functions (Ray ships a
    task by reference to its module, so the workers need this folder on their path)."""
    here = str(Path(__file__).resolve().parent)
    path = os.pathsep.join(p for p in (here, os.environ.get("PYTHONPATH")) if p)
    ray.init(
        num_cpus=num_cpus,
        include_dashboard=False,
        log_to_driver=False,
        runtime_env={"env_vars": {"PYTHONPATH": path}},
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", help="scene file (default: the built-in demo)")
    parser.add_argument("-n", type=int, default=2000)
    parser.add_argument("--shards", type=int, default=8)
    args = parser.parse_args()
    start_local_ray()
    try:
        result = run_batch(mjcf_forge.Scene.load(args.scene), args.n, args.shards)
    finally:
        ray.shutdown()
    print(result)
    if not result["identical"]:
        raise SystemExit("the shards differ from one process")


if __name__ == "__main__":
    main()
