#!/usr/bin/env bash
# Runs every test of mjcf-forge (the README's test command; .ci/run calls it), each
# judgement once (docs/contributing.md, "Tests", says which stage holds which test):
#
#   bash scripts/test.sh            every tier but the full client runs (scripts/test_full.sh)
#   bash scripts/test.sh --quick    a developer's inner loop (under 5 minutes once built):
#                                   fmt, clippy once, the Rust unit tests, one judge per tier
#
# 1. formatting and clippy (with and without MuJoCo, and the Python bindings crate);
# 2. `cargo test` without features: every Rust test and every judge that does not depend
#    on which MuJoCo the build links (the document, prefix, geometry, URDF and merge judges
#    judge what we write with both Python MuJoCos, 3.17.0 and 4.0.0, in this one pass);
# 3. per MuJoCo version the feature `mujoco` links (3.17.0 from .cache/venv, as
#    .cargo/config.toml sets MJCF_FORGE_PYTHON, and 4.0.0 from .cache/venv-mj4 through
#    MJCF_FORGE_MUJOCO_DIR), only the tests that depend on it ($LINKED below: the compile
#    FFI, the caches, the preview, the linked builds' merges and scenes), with the doctests
#    and the documentation's MuJoCo examples once, under 3.17.0;
# 4. the judges' own tests under both versions;
# 5. the Python package's tests under 3.17.0, and those that depend on the installed
#    MuJoCo again under 4.0.0 (and test_last_xml.py under LIBERO's 3.3.1);
# 6. the batched simulators (MuJoCo Warp, MJX) in .cache/venv-sim.
#
# Sets up first (idempotent) and checks that every venv and corpus the tests read is there.
# Under CI=true (.ci/run sets it) a test that would skip fails instead. Prints the seconds of
# each stage, and for the Python stages the peak resident memory of the largest process
# (GNU time's maximum RSS) and of the whole machine over the stage (MemTotal - MemAvailable,
# sampled every second, less what was in use when the stage began); a summary at the end.
# Fuzzing is not part of it (tests/fuzz_regressions.rs replays what it found; campaigns:
# scripts/fuzz.sh).
set -euo pipefail

# The model store across processes (issue 46) is off for the suite: every test's counts of
# compiles and patches are then the same whatever ran before; the store's own tests
# (tests/model_store.rs, python/tests/test_model_store.py) name their folders.
export MJCF_FORGE_STORE=off
cd "$(dirname "${BASH_SOURCE[0]}")/.."
QUICK=0
case "${1:-}" in
  "") ;;
  --quick) QUICK=1 ;;
  *) echo "usage: bash scripts/test.sh [--quick]" >&2; exit 2 ;;
esac

# The Rust tests whose outcome depends on the MuJoCo the build links: run once per version.
LINKED=(mujoco_compile cli_compile model_cache model_store document_cache document_differential
        cli_preview cli_edges scene_batch merge_judge)

SUMMARY=()
STAGE=""
STAGE_START=$SECONDS
stage() { # NAME: ends the stage running, starts NAME
  end_stage
  STAGE="$1"
  STAGE_START=$SECONDS
  echo "== $STAGE [${SECONDS}s in]"
}
end_stage() {
  if [[ -n "$STAGE" ]]; then
    SUMMARY+=("$(printf '%6ss  %s%s' "$((SECONDS - STAGE_START))" "$STAGE" "${MEMORY:-}")")
  fi
  STAGE=""
  MEMORY=""
}
sample_peak() { # FILE: writes the machine's peak used memory (kB) into FILE, every second
  local peak=0 u
  while sleep 1; do u="$(used_kb)"; ((u > peak)) && peak=$u && echo "$peak" >"$1"; done
}
used_kb() { awk '/^MemTotal:/ {t = $2} /^MemAvailable:/ {a = $2} END {print t - a}' /proc/meminfo; }
measured() { # CMD...: runs it, noting its peak memory for the stage's summary line
  local peak_file rss_file sampler before status=0
  peak_file="$(mktemp)"
  rss_file="$(mktemp)"
  before="$(used_kb)"
  echo 0 >"$peak_file"
  sample_peak "$peak_file" &
  sampler=$!
  if [[ -x /usr/bin/time ]]; then
    /usr/bin/time -o "$rss_file" -f '%M' "$@" || status=$?
  else
    "$@" || status=$?
  fi
  kill "$sampler" 2>/dev/null || true
  wait "$sampler" 2>/dev/null || true
  local machine=$(( ($(cat "$peak_file") - before) / 1024 )) largest="?"
  ((machine < 0)) && machine=0
  [[ -s "$rss_file" ]] && largest=$(( $(tail -n1 "$rss_file") / 1024 ))
  MEMORY="${MEMORY:-}  [peak: largest process ${largest} MiB, machine +${machine} MiB]"
  echo "== peak memory: largest process ${largest} MiB, machine +${machine} MiB over the stage"
  rm -f "$peak_file" "$rss_file"
  return "$status"
}
lanes() { # FN...: runs each function at once in the background, each into its own log;
  # prints the logs when all are done, the machine's peak over them, and fails if any failed
  local fn names=("$@") pids=() logs=() status=0 i before peak_file sampler
  mkdir -p .cache/logs
  before="$(used_kb)"
  peak_file="$(mktemp)"
  echo 0 >"$peak_file"
  sample_peak "$peak_file" &
  sampler=$!
  for fn in "$@"; do
    logs+=(".cache/logs/lane-$fn.log")
    # A bash of its own, so that `set -e` holds in it whatever context calls lanes.
    bash -c "set -euo pipefail; $(declare -f used_kb sample_peak measured "$fn"); $(declare -p CLIENT_TESTS); $fn" \
      >".cache/logs/lane-$fn.log" 2>&1 &
    pids+=($!)
  done
  for i in "${!pids[@]}"; do
    if ! wait "${pids[$i]}"; then status=1; echo "== lane ${names[$i]} failed" >>"${logs[$i]}"; fi
  done
  kill "$sampler" 2>/dev/null || true
  wait "$sampler" 2>/dev/null || true
  for i in "${!logs[@]}"; do echo "== lane log ${logs[$i]}"; cat "${logs[$i]}"; done
  local machine=$(( ($(cat "$peak_file") - before) / 1024 ))
  ((machine < 0)) && machine=0
  rm -f "$peak_file"
  MEMORY="  [peak: largest process $(grep -ho 'largest process [0-9?]* MiB' "${logs[@]}" | awk '{print $3}' | sort -n | tail -n1) MiB, machine +${machine} MiB]"
  echo "== peak memory over the lanes: machine +${machine} MiB"
  return "$status"
}
finish() {
  end_stage
  if [[ -n "${CLIENT_SETUP:-}" ]]; then kill "$CLIENT_SETUP" 2>/dev/null || true; fi
  echo "== stages (seconds):"
  printf '%s\n' "${SUMMARY[@]}"
}
trap finish EXIT

stage "setup"
bash scripts/setup.sh
CLIENT_SETUP=""
if ((QUICK == 0)); then
  # The client venvs download and install beside the Rust stages, which read none of them
  # (network and unpacking against compiling); the Python stages wait for them. In order:
  # robosuite 1.5.2 with MuJoCo 3.9.0 (about 300 MB of wheels the first time); LIBERO 0.1.1
  # with robosuite 1.4.0 and MuJoCo 3.3.1, with its assets (550 MB); robosuite 1.4.0 on
  # MuJoCo 2.3.7, the oldest MuJoCo robosuite 1.4.0 accepts (150 MB); MuJoCo Warp, MJX and
  # JAX on CPU with mjcf_forge in .cache/venv-sim (Warp's kernels in .cache/warp-kernels).
  mkdir -p .cache/logs
  ( bash scripts/setup_robosuite_env.sh && bash scripts/setup_libero_env.sh \
      && bash scripts/setup_mj2_env.sh && bash scripts/setup_sim_env.sh ) \
    >.cache/logs/setup-clients.log 2>&1 &
  CLIENT_SETUP=$!
fi
clients_set_up() { # waits for the client venvs, then checks every venv and corpus
  local status=0
  wait "$CLIENT_SETUP" || status=$?
  cat .cache/logs/setup-clients.log
  if ((status != 0)); then
    echo "== the client venvs' setup failed (exit $status): .cache/logs/setup-clients.log" >&2
    exit "$status"
  fi
  bash scripts/check_setup.sh
}

stage "cargo fmt --check, clippy"
cargo fmt --all -- --check
cargo clippy --all-targets -- -D warnings
if ((QUICK == 1)); then
  stage "quick: Rust unit tests, one judge per tier (document, model, batch, caches, switch)"
  cargo test --lib
  # The document tier's judge (207 wheel models under 3.17.0 and 4.0.0), the model tier's
  # (prefixing), the batch tier's scene tests.
  cargo test --test document_judge --test prefix_judge --test scene_batch
  # The package (stubs, docstrings, its examples), the caches' judge on the wheel models'
  # edited values and structural edits, MuJoCo's last loaded XML under the switch.
  .cache/venv/bin/python -m pytest python/tests/test_package.py python/tests/test_last_xml.py \
    python/tests/test_document_cache.py -k "not test_document_cache or wheel_models or structural" \
    -q -p no:cacheprovider
  end_stage
  exit 0
fi
cargo clippy --all-targets --features mujoco -- -D warnings
# The Python bindings crate (the workspace's other member; not built by the commands above).
PYO3_PYTHON="$PWD/.cache/venv/bin/python" cargo clippy -p mjcf-forge-python --all-targets -- -D warnings

stage "cargo test, no features: every test and every judge independent of the linked MuJoCo"
cargo test --all-targets

linked_tests=()
for t in "${LINKED[@]}"; do linked_tests+=(--test "$t"); done
stage "cargo test --features mujoco, MuJoCo 3.17.0: what depends on the linked MuJoCo, doctests"
cargo test --features mujoco --lib --bins "${linked_tests[@]}"
# The doctests (this documentation's Rust blocks among them) and docs.rs's blocks that need
# a build with MuJoCo: once, under 3.17.0.
cargo test --features mujoco --doc
cargo test --features mujoco --test docs
# From 4.0 on the wheel `mujoco` depends on `mujoco-core`, which puts libmujoco.so.4.0.0 and
# include/ into the same `mujoco` folder; the venv's Python says where that is. Its own
# target folder, so the two MuJoCo builds do not evict each other's artifacts (CI, which
# builds each once, sets MJCF_FORGE_MJ4_TARGET=target: the dependencies build once).
stage "cargo test --features mujoco, MuJoCo 4.0.0: what depends on the linked MuJoCo"
MJ4_DIR="$(.cache/venv-mj4/bin/python -c 'import mujoco, os; print(os.path.dirname(mujoco.__file__))')"
MJCF_FORGE_MUJOCO_DIR="$MJ4_DIR" CARGO_TARGET_DIR="${MJCF_FORGE_MJ4_TARGET:-target/mujoco-4}" \
  cargo test --features mujoco --lib --bins "${linked_tests[@]}"

stage "the client venvs (set up beside the Rust stages), every venv and corpus checked"
clients_set_up

stage "judge self-tests (MuJoCo 3.17.0 and 4.0.0)"
.cache/venv/bin/python -m pytest tests/judge -q -p no:cacheprovider
.cache/venv-mj4/bin/python -m pytest tests/judge -q -p no:cacheprovider

# The Python stages run in two lanes at once (each alone leaves one of the two cores idle
# about half the time): the clients lane drives robosuite, LIBERO and the batched
# simulators in venvs of their own, through subprocesses (little memory in pytest itself);
# the package lane runs the package's own tests in-process, under 3.17.0, then 4.0.0 and
# LIBERO's 3.3.1. Each lane writes its log, printed when both are done.
# (Balanced by a fresh clone's run: the clients lane 920 s, the package lane 500 s before
# it took the batched simulators, 240 s, and robosuite's resets and builds, 70 s.)
CLIENT_TESTS=(test_robosuite_clients.py test_libero.py test_robosuite_cover.py)
clients_lane() {
  # robosuite 1.5.2, 1.4.0 (MuJoCo 3.3.1, 2.3.7) and LIBERO, stock against switched.
  local files=()
  for f in "${CLIENT_TESTS[@]}"; do files+=("python/tests/$f"); done
  measured .cache/venv/bin/python -m pytest "${files[@]}" -q -p no:cacheprovider --durations=15
}
package_lane() {
  # (test_batch_sim.py needs MuJoCo Warp and JAX: it runs last, in .cache/venv-sim.)
  local ignored=(--ignore=python/tests/test_batch_sim.py)
  for f in "${CLIENT_TESTS[@]}"; do ignored+=("--ignore=python/tests/$f"); done
  # (robosuite's resets and builds, test_robosuite_resets.py and test_robosuite_use.py, run
  # here too: their drivers run in the robosuite venv, one process at a time.)
  measured .cache/venv/bin/python -m pytest python/tests -q -p no:cacheprovider "${ignored[@]}" --durations=25
  echo "== what depends on the installed MuJoCo: 4.0.0, and LIBERO's 3.3.1"
  measured .cache/venv-mj4/bin/python -m pytest python/tests/test_model_cache.py python/tests/test_world_batch.py \
    python/tests/test_document_cache.py python/tests/test_model_store.py python/tests/test_differential.py python/tests/test_urdf.py \
    python/tests/test_last_xml.py -q -p no:cacheprovider
  # MuJoCo's last loaded XML model under LIBERO's MuJoCo 3.3.1 too, where a write through
  # the held load covers a geom's size and frame (mjcf_forge._copied_back.copied_back).
  local only
  only="$(mktemp -d)"
  ln -s "$(.cache/venv/bin/python -c 'import mjcf_forge, os; print(os.path.dirname(mjcf_forge.__file__))')" "$only/mjcf_forge"
  # And the model store (loaded against compiled, bit for bit) on that client's MuJoCo.
  PYTHONPATH="$only:python/tests" .cache/venv-libero/bin/python -m pytest python/tests/test_last_xml.py \
    python/tests/test_model_store.py -q -p no:cacheprovider
  rm -rf "$only"
  # robosuite's task XMLs (written by the robosuite venv) through a DocumentCache, judged by 4.0.0.
  .cache/venv-mj4/bin/python -m pytest python/tests/test_robosuite_resets.py -k task_xmls -q -p no:cacheprovider
  echo "== batched simulators (MuJoCo Warp, MJX on JAX's CPU backend, CPU MuJoCo) judge WorldBatch"
  measured .cache/venv-sim/bin/python -m pytest python/tests/test_batch_sim.py -q -p no:cacheprovider
}

stage "python: the package (3.17.0, 4.0.0, 3.3.1) beside robosuite's and LIBERO's clients and the batched simulators"
lanes clients_lane package_lane
end_stage
echo "== all tests passed [${SECONDS}s]"
