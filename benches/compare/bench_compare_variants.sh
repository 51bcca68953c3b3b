#!/usr/bin/env bash
# Same-run speed comparison of making randomized variants of benches/scenes/lift5.toml
# (robosuite's table arena, Panda + gripper + mount, 5 objects drawn from 6 robosuite
# object models, placed without overlap, random z rotation and colours), back to back:
#
#  1. mjcf-forge streamed: `generate lift5.toml -n N -o - > /dev/null`, 1 thread and all
#     threads (--threads omitted); variants/s read from `--json` (its seconds count the
#     whole command after start-up: scene load, asset store, every variant, the tar
#     stream to /dev/null);
#  2. mjcf-forge to files: `-o DIR` (one XML per variant, manifest.jsonl, assets/ with
#     45 MB of meshes and textures copied once, one syncfs at the end), 1 and all threads,
#     DIR on the local disk (refused on tmpfs);
#  3. the filesystem's own cost per file: a plain loop (Python os.open/os.write/os.close)
#     creating N files of the variants' mean XML size in an empty folder on the same
#     filesystem, then one syncfs (also reported before the sync);
#  4. robosuite 1.5.2 building the same randomized scene with its own classes,
#     benches/compare/bench_robosuite_variants.py (read its docstring: best and median of RUNS
#     variants, one build each).
# Measurements 1-3 run in REPEATS interleaved rounds; the best of each is kept (mjcf-forge:
# processes of N variants each). Each mjcf-forge process also reports its CPU time
# (user + sys, /usr/bin/time) per variant, and robosuite's script its CPU time per
# variant: on a shared machine that ratio moves less than the wall-clock one.
#
# Prints each measurement, then the ratios:
#  - forge variants/s / robosuite variants/s (against robosuite's best variant, the
#    figure most favourable to robosuite, and against its median);
#  - all threads / 1 thread, streamed and to files;
#  - to files: ms per variant to files / streamed (same thread count); the added cost
#    per file (files - streamed) / the filesystem's cost per file: the "within 1.5x of
#    the filesystem's own cost per file" figure (1.0 = no more than the filesystem).
#
# Usage: bash benches/compare/bench_compare_variants.sh [--rss] [--rss-only]
#   --rss       also: peak memory of RSS_N (default 100000) variants streamed,
#               `/usr/bin/time -v mjcf-forge generate lift5.toml -n RSS_N -o - > /dev/null`
#               ("Maximum resident set size"); takes minutes.
#   --rss-only  only that.
# Env: N (default 5000), REPEATS (default 3), RUNS (robosuite variants, default 50),
#      RSS_N (default 100000), SCRATCH (default target/bench-variants, removed after).
# Needs scripts/setup_robosuite.sh (run here; fast when done).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
N="${N:-5000}"
REPEATS="${REPEATS:-3}"
RUNS="${RUNS:-50}"
RSS_N="${RSS_N:-100000}"
SCRATCH="${SCRATCH:-target/bench-variants}"
SCENE=benches/scenes/lift5.toml
BIN=target/release/mjcf-forge
PY=.cache/venv-robosuite/bin/python

rss=0
compare=1
for arg in "$@"; do
  case "$arg" in
    --rss) rss=1 ;;
    --rss-only) rss=1; compare=0 ;;
    *) echo "bench_compare_variants: unknown argument '$arg' (--rss, --rss-only)" >&2; exit 2 ;;
  esac
done

bash scripts/setup_robosuite.sh >/dev/null
cargo build --release --quiet --features mujoco --bin mjcf-forge
[[ -f "$SCENE" ]] || { echo "bench_compare_variants: $SCENE missing" >&2; exit 1; }

echo "machine: $(nproc) cores;$(uptime | sed 's/.*load average/ load average/')"

if (( rss )); then
  out="$(mktemp)"
  /usr/bin/time -v "$BIN" generate "$SCENE" -n "$RSS_N" -o - --json 2>"$out" >/dev/null \
    || { cat "$out" >&2; rm -f "$out"; echo "bench_compare_variants: generate failed" >&2; exit 1; }
  kb="$(sed -nE 's/^\s*Maximum resident set size \(kbytes\): ([0-9]+)$/\1/p' "$out")"
  json="$(grep '^{' "$out")"
  rm -f "$out"
  [[ -n "$kb" && -n "$json" ]] || { echo "bench_compare_variants: no RSS or summary from /usr/bin/time" >&2; exit 1; }
  "$PY" - "$RSS_N" "$kb" "$json" <<'PY'
import json, sys
n, kb, s = int(sys.argv[1]), int(sys.argv[2]), json.loads(sys.argv[3])
assert s["variants"] == n and not s["failures"], s
print(f"peak RSS, {n} variants streamed (-o - > /dev/null, all threads): {kb / 1024:.1f} MiB "
      f"({kb} kB, /usr/bin/time -v); {s['variants_per_second']:.0f} variants/s, "
      f"{s['xml_bytes'] / 1e9:.2f} GB of XML; target < 200 MB: {'met' if kb * 1024 < 200e6 else 'NOT met'}")
PY
fi
(( compare )) || exit 0

case "$(stat -f -c %T "$(dirname "$SCRATCH")")" in
  tmpfs|ramfs) echo "bench_compare_variants: $SCRATCH is on $(stat -f -c %T "$(dirname "$SCRATCH")"): use a local disk (SCRATCH=...)" >&2; exit 1 ;;
esac
rm -rf "$SCRATCH"
mkdir -p "$SCRATCH"
trap 'rm -rf "$SCRATCH"' EXIT

# One generate run; prints its --json summary (which goes to stderr with -o -) with the
# process's CPU time per variant added (user + sys from /usr/bin/time, scene load included).
forge() { # threads(or "all") output
  local threads=() summary cpu
  [[ "$1" == all ]] || threads=(--threads "$1")
  cpu="$(mktemp)"
  if [[ "$2" == - ]]; then
    summary="$(/usr/bin/time -o "$cpu" -f '%U %S' "$BIN" generate "$SCENE" -n "$N" -o - "${threads[@]}" --json 2>&1 >/dev/null)"
  else
    rm -rf "$2"
    summary="$(/usr/bin/time -o "$cpu" -f '%U %S' "$BIN" generate "$SCENE" -n "$N" -o "$2" "${threads[@]}" --json)"
    local files
    files="$(find "$2" -maxdepth 1 -name '*.xml' | wc -l)"
    [[ "$files" == "$N" ]] || { echo "bench_compare_variants: $files XML files in $2, expected $N" >&2; exit 1; }
    rm -rf "$2"
  fi
  summary="$(grep '^{' <<<"$summary")" || { echo "bench_compare_variants: no summary from generate" >&2; exit 1; }
  "$PY" -c '
import json, sys
s = json.loads(sys.argv[1])
assert s["variants"] == int(sys.argv[3]) and not s["failures"], s
user, system = (float(v) for v in sys.argv[2].split())
s["cpu_ms_per_variant"] = (user + system) * 1e3 / s["variants"]
print(json.dumps(s))
' "$summary" "$(tail -1 "$cpu")" "$N"
  rm -f "$cpu"
}

# The filesystem's own cost per file, one run: a plain loop creating N files of SIZE bytes
# in an empty folder on the same disk, then one syncfs.
fs_loop() { # size
  "$PY" - "$SCRATCH/fs" "$N" "$1" <<'PY'
import ctypes, json, os, shutil, sys, time
folder, n, size = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
data = (b"<mujoco>" + b"x" * size)[:size]
libc = ctypes.CDLL(None, use_errno=True)
shutil.rmtree(folder, ignore_errors=True)
os.makedirs(folder)
t0 = time.perf_counter()
for i in range(n):
    fd = os.open(os.path.join(folder, f"{i:09}.xml"), os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    os.write(fd, data)
    os.close(fd)
t1 = time.perf_counter()
dfd = os.open(folder, os.O_RDONLY)
if libc.syncfs(dfd) != 0:
    raise OSError(ctypes.get_errno(), "syncfs")
os.close(dfd)
t2 = time.perf_counter()
assert len(os.listdir(folder)) == n
shutil.rmtree(folder)
print(json.dumps({"files": n, "bytes_per_file": size, "ms_per_file": (t2 - t0) / n * 1e3,
                  "ms_per_file_unsynced": (t1 - t0) / n * 1e3}))
PY
}

# Keeps the better of two JSON lines by KEY (higher, or lower with "low").
better() { # new best key [low]
  "$PY" -c '
import json, sys
a = json.loads(sys.argv[1]); b = json.loads(sys.argv[2]) if sys.argv[2] else None
key, low = sys.argv[3], len(sys.argv) > 4
print(json.dumps(a if b is None or (a[key] < b[key] if low else a[key] > b[key]) else b))
' "$@"
}

# REPEATS rounds, each measurement once per round (interleaved, so all see the same
# machine); the best of each is kept (highest variants/s; lowest ms per file).
stream1="" streamA="" files1="" filesA="" fsjson=""
bytes_per_file=""
for _ in $(seq "$REPEATS"); do
  stream1="$(better "$(forge 1 -)" "$stream1" variants_per_second)"
  streamA="$(better "$(forge all -)" "$streamA" variants_per_second)"
  [[ -n "$bytes_per_file" ]] || bytes_per_file="$("$PY" -c 'import json,sys; s=json.loads(sys.argv[1]); print(round(s["xml_bytes"]/s["variants"]))' "$stream1")"
  files1="$(better "$(forge 1 "$SCRATCH/out")" "$files1" variants_per_second)"
  fsjson="$(better "$(fs_loop "$bytes_per_file")" "$fsjson" ms_per_file low)"
  filesA="$(better "$(forge all "$SCRATCH/out")" "$filesA" variants_per_second)"
done

# robosuite logs macro warnings on stderr: shown only when the script fails.
rs_err="$(mktemp)"
rs="$("$PY" benches/compare/bench_robosuite_variants.py --runs "$RUNS" 2>"$rs_err")" \
  || { cat "$rs_err" >&2; rm -f "$rs_err"; echo "bench_compare_variants: bench_robosuite_variants.py failed" >&2; exit 1; }
rm -f "$rs_err"

echo "mjcf-forge streamed, 1 thread:     $stream1"
echo "mjcf-forge streamed, all threads:  $streamA"
echo "mjcf-forge to files, 1 thread:     $files1"
echo "mjcf-forge to files, all threads:  $filesA"
echo "filesystem, plain loop:            $fsjson"
echo "robosuite:                         $rs"
"$PY" - "$stream1" "$streamA" "$files1" "$filesA" "$fsjson" "$rs" "$N" "$REPEATS" <<'PY'
import json, sys
s1, sa, f1, fa, fs, rs = (json.loads(a) for a in sys.argv[1:7])
n, repeats = sys.argv[7], sys.argv[8]
rate = lambda s: s["variants_per_second"]
ms = lambda s: 1e3 / rate(s)
print(f"-- ratios (mjcf-forge: best of {repeats} processes of {n} variants; robosuite: {rs['runs']} variants)")
for label, s in (("1 thread", s1), ("all threads", sa)):
    print(f"streamed, {label}: {rate(s):.0f} variants/s = {rate(s) / rs['variants_per_s']:.0f}x robosuite's best "
          f"({rs['variants_per_s']:.1f}/s), {rate(s) / rs['variants_per_s_median']:.0f}x its median "
          f"({rs['variants_per_s_median']:.1f}/s)")
print(f"CPU time per variant (process user + sys): mjcf-forge streamed, 1 thread {s1['cpu_ms_per_variant']:.3f} ms "
      f"(scene load included), robosuite median {rs['median_cpu_ms_per_variant']:.3f} ms (best "
      f"{rs['cpu_ms_per_variant']:.3f} ms): {rs['median_cpu_ms_per_variant'] / s1['cpu_ms_per_variant']:.0f}x "
      f"({rs['cpu_ms_per_variant'] / s1['cpu_ms_per_variant']:.0f}x against robosuite's best)")
print(f"all threads / 1 thread: streamed {rate(sa) / rate(s1):.2f}x, to files {rate(fa) / rate(f1):.2f}x")
fs_ms, fs_uns = fs["ms_per_file"], fs["ms_per_file_unsynced"]
for label, f, s in (("1 thread", f1, s1), ("all threads", fa, sa)):
    added = ms(f) - ms(s)
    print(f"to files, {label}: {rate(f):.0f} variants/s, {ms(f):.3f} ms per variant "
          f"({ms(f) / ms(s):.2f}x streamed); added per file {added:.3f} ms = {added / fs_ms:.2f}x the "
          f"filesystem's {fs_ms:.3f} ms per file with syncfs ({added / fs_uns:.2f}x its "
          f"{fs_uns:.3f} ms unsynced); whole cost per variant {ms(f) / fs_ms:.2f}x the filesystem's per file")
PY
echo "machine after: $(uptime | sed 's/.*load average/load average/')"
